//! One contact point between two solver bodies, in the conventions of the `jostle` crate's ARCHITECTURE.md.

use jostle_math::Vec3;

/// A contact point between body `a` and body `b` (indices into the solver-body slice; either
/// may be [`crate::STATIC_BODY`]).
///
/// Convention (the seed's and Cyclone's): `normal` is unit and points from B toward A, the
/// direction A must move to separate; `penetration` is positive when the bodies overlap and
/// negative when they are apart by that distance (speculative contacts). `point` is where the
/// contact acts on A and `point_b` where it acts on B, in world space: the narrow phase gives
/// each body's own surface point (or, while it holds the point's frame, each body's centre
/// plus the lever arm it held); [`Contact::new`] sets both to the one point given.
///
/// `impulse` is the impulse this contact applied to A during the last step, in contact space:
/// x along the normal, y and z along the tangents of [`jostle_math::contact_basis`] of
/// `normal` (N·s). The narrow phase carries it across steps by feature id; resolvers that warm
/// start read it, and every resolver writes the impulse it applied, so the facade can report
/// contact forces.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Contact {
    /// World-space point where the contact acts on A (m).
    pub point: Vec3,
    /// Penetration depth (m), positive when overlapping.
    pub penetration: f32,
    /// Unit contact normal, from B toward A.
    pub normal: Vec3,
    /// Combined friction coefficient μ (dimensionless). The collision layer mixes the two
    /// materials as sqrt(μa·μb).
    pub friction: f32,
    /// Accumulated contact-space impulse on A (N·s): normal, tangent 1, tangent 2.
    pub impulse: Vec3,
    /// Combined restitution e in [0, 1]; mixed as max(ea, eb).
    pub restitution: f32,
    /// Index of body A in the solver-body slice.
    pub a: u32,
    /// Index of body B in the solver-body slice.
    pub b: u32,
    /// World-space point where the contact acts on B (m).
    pub point_b: Vec3,
    /// The compression (m) the soft step's spring at this point takes as already carried:
    /// learned over the steps from the overlap the point keeps under its load
    /// ([`crate::soft_step::SoftStepSettings::preload_rate`]), so that a loaded contact
    /// rests near [`crate::soft_step::SoftStepSettings::preload_target`] instead of at its
    /// spring's compression. Carried across steps with the impulse; 0 for a new point; the
    /// Millington resolver neither reads nor changes it.
    pub preload: f32,
}

const _: () = assert!(size_of::<Contact>() <= 72);

impl Contact {
    /// A contact with no stored impulse.
    pub fn new(a: u32, b: u32, point: Vec3, normal: Vec3, penetration: f32) -> Self {
        Self {
            point,
            penetration,
            normal,
            friction: 0.0,
            impulse: Vec3::ZERO,
            restitution: 0.0,
            a,
            b,
            point_b: point,
            preload: 0.0,
        }
    }

    /// Sets the combined friction coefficient.
    pub fn with_friction(mut self, friction: f32) -> Self {
        self.friction = friction;
        self
    }

    /// Sets the combined restitution.
    pub fn with_restitution(mut self, restitution: f32) -> Self {
        self.restitution = restitution;
        self
    }
}
