//! The renderer: draws one frame of a [`World`] — sky, ground planes with their grid, shaded
//! bodies, optional contacts — into an RGB image.
//!
//! In: the world's read-only views ([`World::body_views`], [`World::half_space_views`],
//! [`World::contacts`]). Out: an [`RgbImage`]. Buffers are kept between frames, so rendering
//! an animation allocates only the returned image. The camera is fixed at the first frame
//! (the settings' camera, or [`Camera::framing`] of that frame's world) so an animation does
//! not jitter as bodies move.

use crate::camera::{Camera, NEAR, Projection};
use crate::palette::{self, CONTACT_NORMAL, CONTACT_POINT, GRID, GROUND, SKY_HORIZON, SKY_ZENITH};
use crate::raster::{Target, blend, clip_segment, clip_triangle};
use crate::{RenderError, RenderSettings};
use image::RgbImage;
use jostle::{BodyView, PlaneView, Vec3, World};

/// Length of a drawn contact normal (m).
const NORMAL_LENGTH: f32 = 0.3;
/// Relative depth bias of lines and dots, so those lying on a surface stay visible.
const LINE_BIAS: f32 = 2e-3;
/// Grid lines fade out between these sizes of a pixel on the ground (m), before they get
/// close enough to alias into moiré.
const GRID_FADE: (f32, f32) = (0.12, 0.35);
/// How strongly a grid line darkens the ground.
const GRID_STRENGTH: f32 = 0.85;
/// The ground fades into the horizon's colour at this many camera-to-target distances.
const FOG_DISTANCES: f32 = 5.0;

/// Draws worlds into images (see the crate documentation).
pub struct Renderer {
    settings: RenderSettings,
    camera: Option<Camera>,
    target: Target,
    view_vertices: Vec<Vec3>,
    world_vertices: Vec<Vec3>,
}

impl Renderer {
    /// A renderer for images of `settings.width` × `settings.height` pixels. Errors when the
    /// size is zero or above 8192 pixels a side, or the camera is invalid.
    pub fn new(settings: RenderSettings) -> Result<Renderer, RenderError> {
        settings.validate()?;
        let target = Target::new(settings.width as usize, settings.height as usize);
        Ok(Renderer {
            camera: settings.camera,
            settings,
            target,
            view_vertices: Vec::new(),
            world_vertices: Vec::new(),
        })
    }

    /// The camera in use: the settings' camera, or the framing chosen at the first frame
    /// (`None` before it).
    pub fn camera(&self) -> Option<&Camera> {
        self.camera.as_ref()
    }

    /// The settings.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Draws `world` as it is now.
    pub fn render(&mut self, world: &World) -> RgbImage {
        let (w, h) = (self.settings.width, self.settings.height);
        let camera = *self
            .camera
            .get_or_insert_with(|| Camera::framing(world, w as f32 / h as f32));
        let proj = Projection::new(&camera, w, h);
        self.draw_sky(&proj);
        let fog = FOG_DISTANCES * camera.position.distance(camera.target);
        for plane in world.half_space_views() {
            self.draw_plane(&proj, &plane, fog);
        }
        for view in world.body_views() {
            self.draw_body(&proj, &view);
        }
        if self.settings.contacts {
            self.draw_contacts(&proj, world);
        }
        let mut raw = Vec::with_capacity(self.target.color.len() * 3);
        for px in &self.target.color {
            raw.extend_from_slice(px);
        }
        RgbImage::from_raw(w, h, raw).expect("the buffer holds width × height pixels")
    }

    /// Clears depth and paints the sky: a gradient by the elevation of each row's central ray.
    fn draw_sky(&mut self, proj: &Projection) {
        for y in 0..self.target.height {
            let ray = proj.ray(proj.half_w, y as f32 + 0.5).normalize();
            let t = (ray.y * 1.6).clamp(0.0, 1.0);
            let c = palette::to_u8(palette::mix(SKY_HORIZON, SKY_ZENITH, t));
            self.target.clear_row(y, c);
        }
    }

    /// An unbounded plane, ray-cast per pixel: exact at any distance, with a horizon, and
    /// its 1 m grid antialiased by the pixel's footprint on the plane (the screen-space
    /// derivative of the plane coordinates, as a shader's `fwidth`).
    fn draw_plane(&mut self, proj: &Projection, plane: &PlaneView, fog: f32) {
        let n = plane.normal;
        let helper = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
        let u_axis = n.cross(helper).normalize();
        let v_axis = n.cross(u_axis);
        // A point eye + t·ray has depth t; it is on the plane when t = h / (ray·n).
        let h = (plane.point - proj.eye).dot(n);
        let rel = proj.eye - plane.point;
        let (rel_u, rel_v) = (rel.dot(u_axis), rel.dot(v_axis));
        // ray(x, y) = r0 + x·rx + y·ry, so its dot with n, u and v is affine in the pixel.
        let r0 = proj.ray(0.0, 0.0);
        let rx = proj.ray(1.0, 0.0) - r0;
        let ry = proj.ray(0.0, 1.0) - r0;
        let affine = |a: Vec3| (r0.dot(a), rx.dot(a), ry.dot(a));
        let (n0, nx, ny) = affine(n);
        let (u0, ux, uy) = affine(u_axis);
        let (v0, vx, vy) = affine(v_axis);
        // Plane coordinates (u, v) and depth t of the ray through pixel point (x, y).
        let at = |x: f32, y: f32| {
            let t = h / (n0 + nx * x + ny * y);
            (
                rel_u + t * (u0 + ux * x + uy * y),
                rel_v + t * (v0 + vx * x + vy * y),
                t,
            )
        };
        let lit = palette::shade(GROUND, n);
        let lit = [0, 1, 2].map(|k| lit[k] as f32);
        let width = self.target.width;
        for py in 0..self.target.height {
            let y = py as f32 + 0.5;
            for px in 0..width {
                let x = px as f32 + 0.5;
                let (u, v, t) = at(x, y);
                if !(t > NEAR && t.is_finite()) {
                    continue;
                }
                let i = py * width + px;
                let inv_z = 1.0 / t;
                if inv_z <= self.target.depth[i] {
                    continue;
                }
                let (u1, v1, _) = at(x + 1.0, y);
                let (u2, v2, _) = at(x, y + 1.0);
                let line = |c: f32, c1: f32, c2: f32| {
                    let fw = ((c1 - c).abs() + (c2 - c).abs()).max(1e-6);
                    let cover = (1.0 - (c - c.round()).abs() / fw).clamp(0.0, 1.0);
                    let fade = ((GRID_FADE.1 - fw) / (GRID_FADE.1 - GRID_FADE.0)).clamp(0.0, 1.0);
                    cover * fade
                };
                let grid = line(u, u1, u2).max(line(v, v1, v2)) * GRID_STRENGTH;
                let g = blend(palette::to_u8(lit), GRID, grid);
                let f = 1.0 - (-(t / fog).powi(2)).exp();
                let c = palette::mix(g.map(|c| c as f32), SKY_HORIZON, f);
                self.target.depth[i] = inv_z;
                self.target.color[i] = palette::to_u8(c);
            }
        }
    }

    /// A body's mesh: back faces culled (closed meshes), flat Lambert shading from the world
    /// normal, clipped at the near plane, z-buffered.
    fn draw_body(&mut self, proj: &Projection, view: &BodyView) {
        let base = palette::body_color(view.handle.index(), view.fixed, view.sleeping);
        self.world_vertices.clear();
        self.world_vertices
            .extend(view.mesh.vertices.iter().map(|v| view.to_world(*v)));
        self.view_vertices.clear();
        self.view_vertices
            .extend(self.world_vertices.iter().map(|p| proj.to_view(*p)));
        let mut clipped = [Vec3::ZERO; 4];
        for tri in &view.mesh.indices {
            let [a, b, c] = tri.map(|i| i as usize);
            let (wa, wb, wc) = (
                self.world_vertices[a],
                self.world_vertices[b],
                self.world_vertices[c],
            );
            let normal = (wb - wa).cross(wc - wa);
            let facing = normal.dot(proj.eye - wa) > 0.0;
            if !facing && view.mesh.closed {
                continue;
            }
            let Some(normal) = normal.try_normalize() else {
                continue;
            };
            let normal = if facing { normal } else { -normal };
            let color = palette::shade(base, normal);
            let vs = [
                self.view_vertices[a],
                self.view_vertices[b],
                self.view_vertices[c],
            ];
            let count = clip_triangle(vs, &mut clipped);
            if count < 3 {
                continue;
            }
            let s0 = proj.to_screen(clipped[0]);
            for k in 1..count - 1 {
                let s1 = proj.to_screen(clipped[k]);
                let s2 = proj.to_screen(clipped[k + 1]);
                self.target.triangle([s0, s1, s2], color);
            }
        }
    }

    /// The last step's contact points as dots and their normals (B → A) as short lines.
    fn draw_contacts(&mut self, proj: &Projection, world: &World) {
        let radius = (self.target.height as i64 / 240).max(1);
        for c in world.contacts() {
            let (a, b) = (
                proj.to_view(c.point),
                proj.to_view(c.point + c.normal * NORMAL_LENGTH),
            );
            if let Some((a, b)) = clip_segment(a, b) {
                self.target.line(
                    proj.to_screen(a),
                    proj.to_screen(b),
                    CONTACT_NORMAL,
                    LINE_BIAS,
                );
            }
            if let Some(p) = proj.project(c.point) {
                self.target.dot(p, radius, CONTACT_POINT, LINE_BIAS);
            }
        }
    }
}
