//! The perspective camera: where the eye is, what it looks at, and the projection from world
//! space to pixels; and the default framing of a world.
//!
//! In: a [`Camera`] (from code or a scene file) and the image size. Out: a `Projection` that
//! maps world points to view space (x right, y up, z the depth in front of the eye) and view
//! space to pixel coordinates with 1/z for the depth buffer. +Y is up; a camera looking
//! straight up or down uses −Z as its up instead.

use crate::RenderError;
use jostle::{Vec3, World};

/// A perspective camera, +Y up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where the eye is (m).
    pub position: Vec3,
    /// The point drawn at the image's centre (m).
    pub target: Vec3,
    /// Vertical field of view (degrees), in (1, 179).
    pub fov_degrees: f32,
}

impl From<&jostle::scene::Camera> for Camera {
    fn from(c: &jostle::scene::Camera) -> Self {
        Self {
            position: c.position,
            target: c.target,
            fov_degrees: c.fov,
        }
    }
}

/// Field of view of the framing camera (degrees).
const FRAMING_FOV: f32 = 40.0;
/// Direction from the scene's centre to the framing camera: in front (+Z), a little to the
/// right (+X) and raised about 25°, so boxes show three faces and stacks in the XY plane
/// (the generators' pyramids and walls) face the viewer.
const FRAMING_DIR: Vec3 = Vec3::new(0.42, 0.5, 1.0);
/// Fraction of the image the framed bounding box may fill, each way.
const FRAMING_FILL: f32 = 0.95;

impl Camera {
    /// Checks the numbers: finite, fov in (1, 179) degrees, position ≠ target.
    pub fn validate(&self) -> Result<(), RenderError> {
        let bad = |m: String| Err(RenderError::Settings(format!("camera: {m}")));
        if !(self.position.is_finite() && self.target.is_finite()) {
            return bad(format!(
                "position {} and target {} must be finite",
                self.position, self.target
            ));
        }
        if !(self.fov_degrees.is_finite() && self.fov_degrees > 1.0 && self.fov_degrees < 179.0) {
            return bad(format!(
                "fov must be in (1, 179) degrees, got {}",
                self.fov_degrees
            ));
        }
        if self.position.distance(self.target) <= 1e-4 {
            return bad("position and target must differ".into());
        }
        Ok(())
    }

    /// A camera that frames every body of `world` with a finite shape (half-spaces excluded):
    /// the bounding box of their meshes' bounding spheres, seen from a raised oblique angle
    /// (front, slightly right, ~25° up) at the distance where the box fills 95% of an image of
    /// this aspect ratio (width / height). An empty world gives a view of the origin.
    pub fn framing(world: &World, aspect: f32) -> Camera {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for view in world.body_views() {
            let r = Vec3::splat(view.mesh.bounding_radius());
            if view.position.is_finite() {
                lo = lo.min(view.position - r);
                hi = hi.max(view.position + r);
            }
        }
        if !(lo.is_finite() && hi.is_finite()) {
            lo = Vec3::splat(-1.0);
            hi = Vec3::splat(1.0);
        }
        Self::framing_box(lo, hi, aspect)
    }

    /// The framing camera of the box `lo`..`hi` (see [`Camera::framing`]).
    pub fn framing_box(lo: Vec3, hi: Vec3, aspect: f32) -> Camera {
        let centre = (lo + hi) * 0.5;
        let dir = FRAMING_DIR.normalize();
        let basis = Basis::looking(-dir);
        let tan_v = (FRAMING_FOV.to_radians() * 0.5).tan() * FRAMING_FILL;
        let tan_h = tan_v * aspect.max(1e-3);
        // For each corner at (x, y, z) in the camera's basis, with the eye at distance d
        // behind the centre, the corner's depth is d + z: it fits when |x| ≤ tan_h (d + z)
        // and |y| ≤ tan_v (d + z).
        let mut distance: f32 = 0.0;
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let r = corner - centre;
            let (x, y, z) = (r.dot(basis.right), r.dot(basis.up), r.dot(basis.forward));
            distance = distance.max(x.abs() / tan_h - z).max(y.abs() / tan_v - z);
        }
        let distance = distance.max(1.0);
        Camera {
            position: centre + dir * distance,
            target: centre,
            fov_degrees: FRAMING_FOV,
        }
    }
}

/// An orthonormal camera basis.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Basis {
    pub right: Vec3,
    pub up: Vec3,
    pub forward: Vec3,
}

impl Basis {
    /// The basis looking along `forward` (any length > 0) with +Y up, or −Z up when looking
    /// (nearly) straight up or down.
    pub fn looking(forward: Vec3) -> Basis {
        let forward = forward.normalize();
        let world_up = if forward.cross(Vec3::Y).length_squared() < 1e-6 {
            Vec3::NEG_Z
        } else {
            Vec3::Y
        };
        let right = forward.cross(world_up).normalize();
        let up = right.cross(forward);
        Basis { right, up, forward }
    }
}

/// The near plane's distance (m): geometry closer to the eye is clipped away.
pub(crate) const NEAR: f32 = 0.05;

/// World → view → pixels for one camera and image size.
#[derive(Clone, Debug)]
pub(crate) struct Projection {
    pub eye: Vec3,
    pub basis: Basis,
    /// Pixels per unit of x/z and y/z.
    pub scale_x: f32,
    pub scale_y: f32,
    pub half_w: f32,
    pub half_h: f32,
}

impl Projection {
    pub fn new(camera: &Camera, width: u32, height: u32) -> Projection {
        let half_w = width as f32 * 0.5;
        let half_h = height as f32 * 0.5;
        let focal = half_h / (camera.fov_degrees.to_radians() * 0.5).tan();
        Projection {
            eye: camera.position,
            basis: Basis::looking(camera.target - camera.position),
            scale_x: focal,
            scale_y: focal,
            half_w,
            half_h,
        }
    }

    /// A world point in view space: (right, up, depth in front of the eye).
    pub fn to_view(&self, p: Vec3) -> Vec3 {
        let r = p - self.eye;
        Vec3::new(
            r.dot(self.basis.right),
            r.dot(self.basis.up),
            r.dot(self.basis.forward),
        )
    }

    /// A view-space point in front of the near plane → (pixel x, pixel y, 1/depth).
    pub fn to_screen(&self, v: Vec3) -> [f32; 3] {
        let inv_z = 1.0 / v.z;
        [
            self.half_w + self.scale_x * v.x * inv_z,
            self.half_h - self.scale_y * v.y * inv_z,
            inv_z,
        ]
    }

    /// A world point → pixel coordinates, or `None` behind the near plane.
    pub fn project(&self, p: Vec3) -> Option<[f32; 3]> {
        let v = self.to_view(p);
        (v.z > NEAR).then(|| self.to_screen(v))
    }

    /// The world direction of the ray through pixel coordinates (x, y), scaled so that its
    /// component along the view direction is 1 (a point at ray parameter t has depth t).
    pub fn ray(&self, x: f32, y: f32) -> Vec3 {
        self.basis.forward
            + self.basis.right * ((x - self.half_w) / self.scale_x)
            + self.basis.up * ((self.half_h - y) / self.scale_y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_projects_to_the_centre_and_up_is_up() {
        let cam = Camera {
            position: Vec3::new(3.0, 4.0, 10.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            fov_degrees: 45.0,
        };
        let p = Projection::new(&cam, 640, 480);
        let [x, y, inv_z] = p.project(cam.target).unwrap();
        assert!((x - 320.0).abs() < 1e-3 && (y - 240.0).abs() < 1e-3);
        assert!((1.0 / inv_z - cam.position.distance(cam.target)).abs() < 1e-3);
        let [_, y_up, _] = p.project(cam.target + Vec3::Y).unwrap();
        assert!(y_up < 240.0, "higher points are drawn higher");
        let [x_r, _, _] = p.project(cam.target + p.basis.right).unwrap();
        assert!(x_r > 320.0);
        assert!(p.project(cam.position - p.basis.forward).is_none());
        // The ray through a pixel passes through what projects there.
        let q = Vec3::new(1.0, 2.0, -1.0);
        let [qx, qy, qz] = p.project(q).unwrap();
        let back = cam.position + p.ray(qx, qy) / qz;
        assert!(back.distance(q) < 1e-3, "{back} vs {q}");
    }

    #[test]
    fn framing_keeps_the_box_in_view() {
        let (lo, hi) = (Vec3::new(-10.0, 0.0, -1.0), Vec3::new(10.0, 20.0, 1.0));
        let cam = Camera::framing_box(lo, hi, 4.0 / 3.0);
        cam.validate().unwrap();
        let p = Projection::new(&cam, 640, 480);
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let [x, y, _] = p.project(c).unwrap();
            assert!(
                (0.0..=640.0).contains(&x) && (0.0..=480.0).contains(&y),
                "{c}: {x} {y}"
            );
        }
        let looking_down = Basis::looking(Vec3::NEG_Y);
        assert!(looking_down.right.is_finite() && looking_down.up.is_finite());
    }
}
