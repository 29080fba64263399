//! jostle-render draws jostle worlds offline: a small software rasteriser that turns a
//! [`World`](jostle::World) into an RGB image, and a GIF writer for animations. No GPU, no
//! window: it runs in CI and on servers.
//!
//! In: the facade's read-only views of a world (bodies' display meshes and poses, half-space
//! planes, contacts) and [`RenderSettings`]. Out: `image::RgbImage`s, saved as PNG with
//! `image`, or appended to a [`GifWriter`]. It depends on the facade `jostle`, `image` and
//! `thiserror` only: never on parry or the engine's layers.
//!
//! What a frame shows: a sky gradient; every half-space as an unbounded plane with a 1 m grid,
//! fading into the horizon; every other body's mesh with flat Lambert shading from a fixed sun
//! plus ambient, in a colour chosen by its index (grey when fixed, blue-grey when asleep);
//! optionally the last step's contact points (red dots) and normals (yellow, 0.3 m, from B
//! toward A). Depth is exact per pixel (1/z interpolation).
//!
//! ```
//! use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};
//! use jostle_render::{RenderSettings, Renderer};
//!
//! let mut world = World::new(WorldSettings::default());
//! world.add_body(BodyDesc::fixed("ground", ShapeDesc::HalfSpace { normal: Vec3::Y })).unwrap();
//! world
//!     .add_body(BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.5 }).at(Vec3::Y))
//!     .unwrap();
//! let mut renderer = Renderer::new(RenderSettings { width: 160, height: 120, ..Default::default() })
//!     .unwrap();
//! let image = renderer.render(&world);
//! assert_eq!(image.dimensions(), (160, 120));
//! ```
#![deny(missing_docs)]

pub mod camera;
pub mod gif;
mod palette;
mod raster;
pub mod renderer;

pub use camera::Camera;
pub use gif::GifWriter;
pub use image;
pub use renderer::Renderer;

use thiserror::Error;

/// The largest image side accepted (pixels).
pub const MAX_SIDE: u32 = 8192;

/// What to draw and how big.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width (pixels), 1 to [`MAX_SIDE`]. Default 640.
    pub width: u32,
    /// Image height (pixels), 1 to [`MAX_SIDE`]. Default 480.
    pub height: u32,
    /// The camera. Default `None`: frame the world at the first frame ([`Camera::framing`]).
    pub camera: Option<Camera>,
    /// Draw the last step's contact points and normals. Default false.
    pub contacts: bool,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            camera: None,
            contacts: false,
        }
    }
}

impl RenderSettings {
    /// Checks the size and the camera.
    pub fn validate(&self) -> Result<(), RenderError> {
        for (name, side) in [("width", self.width), ("height", self.height)] {
            if !(1..=MAX_SIDE).contains(&side) {
                return Err(RenderError::Settings(format!(
                    "image {name} must be in 1..={MAX_SIDE} pixels, got {side}"
                )));
            }
        }
        if let Some(camera) = &self.camera {
            camera.validate()?;
        }
        Ok(())
    }
}

/// Why rendering or writing an image failed.
#[derive(Debug, Error)]
pub enum RenderError {
    /// A setting is out of range (size, camera, frame rate).
    #[error("{0}")]
    Settings(String),
    /// Encoding the image failed.
    #[error(transparent)]
    Image(#[from] image::ImageError),
    /// Writing the image failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}
