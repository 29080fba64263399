//! Animated GIF output: frames from the renderer in, one looping GIF out.
//!
//! Encoding goes through `image`'s GIF codec: each frame gets its own 256-colour palette
//! (NeuQuant at [`GIF_SPEED`]), so colours stay faithful as the scene changes. Quantising and
//! compressing a frame costs more than drawing it, so it runs on a worker thread that owns the
//! writer: the caller simulates and draws the next frame meanwhile (two cores, about half the
//! wall time). At most [`QUEUE`] frames wait, so an animation of any length needs the memory
//! of a few frames.

use crate::RenderError;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, DynamicImage, Frame, RgbImage};
use std::io::Write;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

/// NeuQuant's sampling factor (1 = best and slowest, 30 = fastest). 10 keeps a frame's
/// quantisation to a few tens of milliseconds at 640×480 with no visible loss on flat-shaded
/// scenes.
pub const GIF_SPEED: i32 = 10;

/// The largest frame rate accepted: GIF delays are whole hundredths of a second and browsers
/// slow anything under 2 of them down, so 50 frames per second is the fastest that plays.
pub const MAX_FPS: u32 = 50;

/// Frames that may wait for the encoder before [`GifWriter::push`] blocks.
pub const QUEUE: usize = 3;

/// Writes frames of equal size into a looping GIF, encoding on a worker thread.
pub struct GifWriter<W: Write + Send + 'static> {
    sender: Option<SyncSender<RgbImage>>,
    worker: Option<JoinHandle<Result<W, RenderError>>>,
    size: Option<(u32, u32)>,
    frames: usize,
}

impl<W: Write + Send + 'static> GifWriter<W> {
    /// A GIF that plays `fps` frames per second (1 to [`MAX_FPS`]; the delay is rounded to
    /// whole hundredths of a second) and loops forever, written into `writer`.
    pub fn new(writer: W, fps: u32) -> Result<Self, RenderError> {
        if !(1..=MAX_FPS).contains(&fps) {
            return Err(RenderError::Settings(format!(
                "fps must be in 1..={MAX_FPS}, got {fps}"
            )));
        }
        let centiseconds = (100.0 / fps as f64).round().max(2.0) as u32;
        let delay = Delay::from_numer_denom_ms(centiseconds * 10, 1);
        let (sender, receiver) = sync_channel(QUEUE);
        let worker = std::thread::Builder::new()
            .name("jostle-gif".into())
            .spawn(move || encode(writer, receiver, delay))
            .map_err(RenderError::Io)?;
        Ok(Self {
            sender: Some(sender),
            worker: Some(worker),
            size: None,
            frames: 0,
        })
    }

    /// Appends a frame; every frame must have the first one's size. Blocks while [`QUEUE`]
    /// frames wait for the encoder. An encoding or write error of an earlier frame is
    /// reported here or by [`GifWriter::finish`].
    pub fn push(&mut self, frame: RgbImage) -> Result<(), RenderError> {
        let size = frame.dimensions();
        match self.size {
            None => self.size = Some(size),
            Some(first) if first != size => {
                return Err(RenderError::Settings(format!(
                    "GIF frames must all be {}x{}, got {}x{}",
                    first.0, first.1, size.0, size.1
                )));
            }
            Some(_) => {}
        }
        let sent = self.sender.as_ref().map(|s| s.send(frame).is_ok());
        if sent != Some(true) {
            // The worker stopped: it failed, and its error says why.
            return Err(self.join().err().unwrap_or_else(|| {
                RenderError::Io(std::io::Error::other("the GIF encoder stopped"))
            }));
        }
        self.frames += 1;
        Ok(())
    }

    /// Frames pushed so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Ends the GIF: waits for the encoder, writes the trailer, flushes and returns the
    /// writer, or the first error met.
    pub fn finish(mut self) -> Result<W, RenderError> {
        self.join()
    }

    fn join(&mut self) -> Result<W, RenderError> {
        self.sender = None; // closes the channel: the worker ends after the queued frames
        let worker = self.worker.take().ok_or_else(|| {
            RenderError::Io(std::io::Error::other("the GIF was already finished"))
        })?;
        worker.join().unwrap_or_else(|_| {
            Err(RenderError::Io(std::io::Error::other(
                "the GIF encoder thread panicked",
            )))
        })
    }
}

impl<W: Write + Send + 'static> Drop for GifWriter<W> {
    fn drop(&mut self) {
        if self.worker.is_some() {
            let _ = self.join();
        }
    }
}

/// The worker: encodes frames until the channel closes, then ends the GIF and flushes.
fn encode<W: Write>(
    mut writer: W,
    frames: Receiver<RgbImage>,
    delay: Delay,
) -> Result<W, RenderError> {
    {
        let mut encoder = GifEncoder::new_with_speed(&mut writer, GIF_SPEED);
        encoder.set_repeat(Repeat::Infinite)?;
        for frame in frames {
            let rgba = DynamicImage::ImageRgb8(frame).into_rgba8();
            encoder.encode_frame(Frame::from_parts(rgba, 0, 0, delay))?;
        }
        // Dropping the encoder writes the GIF trailer.
    }
    writer.flush()?;
    Ok(writer)
}
