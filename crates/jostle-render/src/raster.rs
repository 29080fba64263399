//! The rasteriser: a colour buffer and a depth buffer, filled with depth-tested triangles,
//! lines and dots, and near-plane clipping of view-space geometry.
//!
//! In: screen-space vertices `[x, y, 1/z]` (pixels, reciprocal view depth) and flat colours.
//! Out: pixels. 1/z is affine in screen space, so interpolating it linearly gives the exact
//! depth of every pixel (no perspective error in the z-test); the buffer keeps the largest
//! 1/z (the nearest surface), 0 meaning "nothing drawn". Triangles are filled by
//! bounding-box scan with edge functions in f64 (clipped vertices near the eye project far
//! outside the image, where f32 edge functions would crack). Knows nothing of worlds.

use crate::camera::NEAR;
use jostle::Vec3;

/// A screen-space vertex: pixel x, pixel y, 1/depth.
pub(crate) type ScreenVertex = [f32; 3];

/// Colour and depth buffers of one image.
pub(crate) struct Target {
    pub width: usize,
    pub height: usize,
    pub color: Vec<[u8; 3]>,
    pub depth: Vec<f32>,
}

impl Target {
    pub fn new(width: usize, height: usize) -> Target {
        Target {
            width,
            height,
            color: vec![[0; 3]; width * height],
            depth: vec![0.0; width * height],
        }
    }

    /// Fills row `y` with `color` and clears its depth.
    pub fn clear_row(&mut self, y: usize, color: [u8; 3]) {
        let row = y * self.width..(y + 1) * self.width;
        self.color[row.clone()].fill(color);
        self.depth[row].fill(0.0);
    }

    /// Fills a triangle (either winding) with a flat colour where it is nearer than what is
    /// drawn. A pixel is covered when its centre is inside or on an edge.
    pub fn triangle(&mut self, v: [ScreenVertex; 3], color: [u8; 3]) {
        let [a, b, c] = v.map(|p| [p[0] as f64, p[1] as f64, p[2] as f64]);
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area == 0.0 || !area.is_finite() {
            return;
        }
        // Orient counter-clockwise in pixel space (y down), so inside means all edges ≥ 0.
        let (b, c, area) = if area < 0.0 {
            (c, b, -area)
        } else {
            (b, c, area)
        };
        let min_x = a[0].min(b[0]).min(c[0]).floor().max(0.0);
        let max_x = a[0].max(b[0]).max(c[0]).ceil().min(self.width as f64 - 1.0);
        let min_y = a[1].min(b[1]).min(c[1]).floor().max(0.0);
        let max_y = a[1]
            .max(b[1])
            .max(c[1])
            .ceil()
            .min(self.height as f64 - 1.0);
        if min_x > max_x || min_y > max_y {
            return;
        }
        // edge(p, q)(s) = (q − p) × (s − p); it is +area at the opposite vertex.
        let edge = |p: [f64; 3], q: [f64; 3]| {
            let dx = p[1] - q[1]; // ∂/∂x
            let dy = q[0] - p[0]; // ∂/∂y
            let at = |x: f64, y: f64| (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]);
            (dx, dy, at(min_x + 0.5, min_y + 0.5))
        };
        let (e0dx, e0dy, mut e0row) = edge(b, c); // weight of a
        let (e1dx, e1dy, mut e1row) = edge(c, a); // weight of b
        let (e2dx, e2dy, mut e2row) = edge(a, b); // weight of c
        let inv_area = 1.0 / area;
        // 1/z as an affine function of the pixel: z = z0 + zdx·Δx + zdy·Δy.
        let zdx = (e0dx * a[2] + e1dx * b[2] + e2dx * c[2]) * inv_area;
        let zdy = (e0dy * a[2] + e1dy * b[2] + e2dy * c[2]) * inv_area;
        let mut zrow = (e0row * a[2] + e1row * b[2] + e2row * c[2]) * inv_area;
        let (x0, x1) = (min_x as usize, max_x as usize);
        for y in min_y as usize..=max_y as usize {
            let (mut e0, mut e1, mut e2, mut z) = (e0row, e1row, e2row, zrow);
            let row = y * self.width;
            let mut inside_seen = false;
            for x in x0..=x1 {
                if e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0 {
                    inside_seen = true;
                    let i = row + x;
                    let zf = z as f32;
                    if zf > self.depth[i] {
                        self.depth[i] = zf;
                        self.color[i] = color;
                    }
                } else if inside_seen {
                    break; // a triangle's span on a row is contiguous
                }
                e0 += e0dx;
                e1 += e1dx;
                e2 += e2dx;
                z += zdx;
            }
            e0row += e0dy;
            e1row += e1dy;
            e2row += e2dy;
            zrow += zdy;
        }
    }

    /// Blends `color` into pixel (x, y) with weight `alpha` if `inv_z` passes the depth test
    /// with a relative `bias` (so that lines and dots lying on a surface are not hidden by it).
    fn plot(&mut self, x: i64, y: i64, inv_z: f32, bias: f32, color: [u8; 3], alpha: f32) {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            return;
        }
        let i = y as usize * self.width + x as usize;
        if inv_z * (1.0 + bias) >= self.depth[i] {
            self.color[i] = blend(self.color[i], color, alpha);
        }
    }

    /// A one-pixel line between two screen vertices, depth-tested with a relative `bias`.
    pub fn line(&mut self, a: ScreenVertex, b: ScreenVertex, color: [u8; 3], bias: f32) {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let steps = dx.abs().max(dy.abs()).ceil().clamp(1.0, 100_000.0) as usize;
        for s in 0..=steps {
            let t = s as f32 / steps as f32;
            let x = a[0] + dx * t;
            let y = a[1] + dy * t;
            let z = a[2] + (b[2] - a[2]) * t;
            self.plot(x.floor() as i64, y.floor() as i64, z, bias, color, 1.0);
        }
    }

    /// A filled square dot of half-size `radius` pixels, depth-tested with a relative `bias`.
    pub fn dot(&mut self, p: ScreenVertex, radius: i64, color: [u8; 3], bias: f32) {
        let (cx, cy) = (p[0].floor() as i64, p[1].floor() as i64);
        for y in cy - radius..=cy + radius {
            for x in cx - radius..=cx + radius {
                self.plot(x, y, p[2], bias, color, 1.0);
            }
        }
    }
}

/// `a` moved toward `b` by `t` in [0, 1].
pub(crate) fn blend(a: [u8; 3], b: [u8; 3], t: f32) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    [0, 1, 2].map(|k| (a[k] as f32 + (b[k] as f32 - a[k] as f32) * t + 0.5) as u8)
}

/// Clips a view-space triangle against the near plane (z = [`NEAR`]); the result is a convex
/// polygon of 0, 3 or 4 vertices, written to `out`, its vertex count returned.
pub(crate) fn clip_triangle(v: [Vec3; 3], out: &mut [Vec3; 4]) -> usize {
    let inside = v.map(|p| p.z >= NEAR);
    match inside.iter().filter(|&&i| i).count() {
        3 => {
            out[..3].copy_from_slice(&v);
            3
        }
        0 => 0,
        _ => {
            // Sutherland–Hodgman against one plane.
            let mut n = 0;
            for i in 0..3 {
                let (p, q) = (v[i], v[(i + 1) % 3]);
                let (pin, qin) = (inside[i], inside[(i + 1) % 3]);
                if pin {
                    out[n] = p;
                    n += 1;
                }
                if pin != qin {
                    let t = (NEAR - p.z) / (q.z - p.z);
                    out[n] = p + (q - p) * t;
                    out[n].z = NEAR;
                    n += 1;
                }
            }
            n
        }
    }
}

/// Clips a view-space segment to the near plane; `None` if it is wholly behind it.
pub(crate) fn clip_segment(a: Vec3, b: Vec3) -> Option<(Vec3, Vec3)> {
    match (a.z >= NEAR, b.z >= NEAR) {
        (true, true) => Some((a, b)),
        (false, false) => None,
        (a_in, _) => {
            let t = (NEAR - a.z) / (b.z - a.z);
            let mut m = a + (b - a) * t;
            m.z = NEAR;
            Some(if a_in { (a, m) } else { (m, b) })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangles_cover_their_inside_and_the_nearest_wins() {
        let mut t = Target::new(10, 10);
        for y in 0..10 {
            t.clear_row(y, [0, 0, 0]);
        }
        // A far triangle covering the lower-left half, then a near one over the same area.
        let far = [[0.0, 0.0, 0.1], [10.0, 10.0, 0.1], [0.0, 10.0, 0.1]];
        t.triangle(far, [10, 0, 0]);
        assert_eq!(t.color[8 * 10 + 1], [10, 0, 0], "inside");
        assert_eq!(t.color[10 + 8], [0, 0, 0], "outside");
        let near = [[0.0, 0.0, 0.5], [0.0, 10.0, 0.5], [10.0, 10.0, 0.5]];
        t.triangle(near, [0, 20, 0]);
        assert_eq!(
            t.color[8 * 10 + 1],
            [0, 20, 0],
            "the nearer one, either winding"
        );
        t.triangle(far, [10, 0, 0]);
        assert_eq!(
            t.color[8 * 10 + 1],
            [0, 20, 0],
            "a farther one stays hidden"
        );
        assert!((t.depth[8 * 10 + 1] - 0.5).abs() < 1e-6);
    }

    #[test]
    fn near_clipping_keeps_the_visible_part() {
        let mut out = [Vec3::ZERO; 4];
        let tri = [
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(-1.0, 0.0, 1.0),
        ];
        assert_eq!(clip_triangle(tri, &mut out), 4);
        assert!(out.iter().all(|p| p.z >= NEAR - 1e-6));
        let behind = tri.map(|p| p - Vec3::Z * 5.0);
        assert_eq!(clip_triangle(behind, &mut out), 0);
        let (a, b) = clip_segment(Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.0, 0.0, 1.0)).unwrap();
        assert_eq!((a.z, b.z), (NEAR, 1.0));
    }
}
