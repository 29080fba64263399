//! Elements that several threads of one soft step read and write at once, each its own.
//!
//! The soft step's passes go colour by colour ([`super::batch`]): the batches of one colour
//! write disjoint bodies, so the threads of [`super::team`] share one colour's batches among
//! them. Each thread then reads and writes body states by index in the same array, which a
//! `&mut [T]` per thread cannot express (two threads would hold overlapping mutable slices).
//! [`Shared`] is the element type of such an array: `share` turns `&mut [T]` into
//! `&[Shared<T>]`, which every thread may hold, and every access to an element is `unsafe`,
//! with the contract that no thread writes an element another reads or writes at the same
//! time. The colouring is what keeps that contract; the kernels name it where they access.

use std::cell::UnsafeCell;

/// One element of an array that several threads access, each a different element
/// ([`share`]). The same layout as `T`.
#[repr(transparent)]
pub struct Shared<T>(UnsafeCell<T>);

// SAFETY: every access to the value is through the `unsafe` methods below, whose contract
// excludes data races; moving the values between threads needs `T: Send`.
unsafe impl<T: Send> Sync for Shared<T> {}

impl<T> Shared<T> {
    /// The element, to read.
    ///
    /// # Safety
    /// No other thread writes this element while the reference lives.
    #[inline(always)]
    pub unsafe fn get(&self) -> &T {
        // SAFETY: the caller's contract: no concurrent writer.
        unsafe { &*self.0.get() }
    }

    /// The element, to write.
    ///
    /// # Safety
    /// No other reference to this element (from this thread or another) is used while the
    /// returned one lives.
    #[inline(always)]
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn get_mut(&self) -> &mut T {
        // SAFETY: the caller's contract: this is the only live reference.
        unsafe { &mut *self.0.get() }
    }
}

/// The array as shared elements, borrowed from `slice` (as `Cell::from_mut` does for one
/// value).
#[inline(always)]
pub fn share<T>(slice: &mut [T]) -> &[Shared<T>] {
    // SAFETY: `Shared<T>` is `repr(transparent)` over `UnsafeCell<T>`, itself
    // `repr(transparent)` over `T`; the unique borrow of `slice` is held for the result's
    // lifetime, so nothing else reaches the elements meanwhile.
    unsafe { &*(slice as *mut [T] as *const [Shared<T>]) }
}

/// One shared value, borrowed from `value` ([`share`] for a single value).
#[inline(always)]
pub fn share_one<T>(value: &mut T) -> &Shared<T> {
    // SAFETY: as in `share`.
    unsafe { &*(value as *mut T as *const Shared<T>) }
}

/// The elements `range` as an ordinary mutable slice.
///
/// # Safety
/// No other reference to any element of `range` is used while the slice lives.
#[inline(always)]
#[allow(clippy::mut_from_ref)]
pub unsafe fn slice_mut<T>(shared: &[Shared<T>], range: std::ops::Range<usize>) -> &mut [T] {
    let part = &shared[range];
    // SAFETY: `Shared<T>` has `T`'s layout (see `share`), the elements are contiguous, and
    // the caller guarantees exclusive access to them; `UnsafeCell` permits the mutation
    // through a shared borrow of the array.
    unsafe { std::slice::from_raw_parts_mut(part.as_ptr() as *mut T, part.len()) }
}
