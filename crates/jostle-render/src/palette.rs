//! Colours and shading: per-body colours, the state tints, the sky, the ground and the light.
//!
//! In: a body's index and state, a surface normal. Out: 8-bit sRGB colours. Flat Lambert
//! shading from one fixed sun direction plus ambient; no gamma handling (the colours are
//! picked to look right as they are).

use jostle::Vec3;

/// Direction toward the sun (unit): above, a little to the right of and in front of the
/// default camera, so that the top, front and side of a box get three different shades.
pub(crate) fn light_dir() -> Vec3 {
    Vec3::new(0.35, 1.0, 0.55).normalize()
}

/// Light that reaches every face, and the share added by the sun at normal incidence.
const AMBIENT: f32 = 0.38;
const DIFFUSE: f32 = 0.62;

/// Colour of the sky at the horizon and straight up.
pub(crate) const SKY_HORIZON: [f32; 3] = [226.0, 233.0, 242.0];
pub(crate) const SKY_ZENITH: [f32; 3] = [142.0, 176.0, 222.0];
/// Colour of a lit ground plane and of its grid lines.
pub(crate) const GROUND: [f32; 3] = [196.0, 192.0, 180.0];
pub(crate) const GRID: [u8; 3] = [120, 118, 110];
/// Contact points and normals.
pub(crate) const CONTACT_POINT: [u8; 3] = [220, 30, 30];
pub(crate) const CONTACT_NORMAL: [u8; 3] = [250, 210, 20];

/// Base colour of fixed bodies.
const FIXED: [f32; 3] = [150.0, 150.0, 150.0];
/// The blue-grey that sleeping bodies are pulled toward, and by how much.
const SLEEP_TINT: [f32; 3] = [125.0, 140.0, 170.0];
const SLEEP_MIX: f32 = 0.55;

/// The base colour of a body: a hue from its index (golden-ratio steps, so neighbours differ),
/// grey when fixed, desaturated toward blue-grey when asleep.
pub(crate) fn body_color(index: u32, fixed: bool, sleeping: bool) -> [f32; 3] {
    if fixed {
        return FIXED;
    }
    let hue = (0.08 + index as f32 * 0.618_034).fract();
    let c = hsv(hue, 0.62, 0.92);
    if sleeping {
        mix(c, SLEEP_TINT, SLEEP_MIX)
    } else {
        c
    }
}

/// `base` lit by the sun on a face with unit normal `n`.
pub(crate) fn shade(base: [f32; 3], n: Vec3) -> [u8; 3] {
    let k = AMBIENT + DIFFUSE * n.dot(light_dir()).max(0.0);
    base.map(|c| (c * k).clamp(0.0, 255.0) as u8)
}

pub(crate) fn mix(a: [f32; 3], b: [f32; 3], t: f32) -> [f32; 3] {
    [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * t)
}

pub(crate) fn to_u8(c: [f32; 3]) -> [u8; 3] {
    c.map(|v| (v + 0.5).clamp(0.0, 255.0) as u8)
}

/// HSV (each in [0, 1]) to RGB in [0, 255].
fn hsv(h: f32, s: f32, v: f32) -> [f32; 3] {
    let h6 = h * 6.0;
    let f = h6.fract();
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    let rgb = match h6 as u32 % 6 {
        0 => [v, t, p],
        1 => [q, v, p],
        2 => [p, v, t],
        3 => [p, q, v],
        4 => [t, p, v],
        _ => [v, p, q],
    };
    rgb.map(|c| c * 255.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_differ_by_index_and_state() {
        let a = body_color(1, false, false);
        assert_ne!(to_u8(a), to_u8(body_color(2, false, false)));
        let asleep = body_color(1, false, true);
        let spread = |c: [f32; 3]| {
            c.iter().cloned().fold(0.0, f32::max) - c.iter().cloned().fold(255.0, f32::min)
        };
        assert!(
            spread(asleep) < spread(a),
            "sleeping bodies are less saturated"
        );
        assert_eq!(body_color(7, true, false), FIXED);
        assert!(shade(a, light_dir())[0] > shade(a, -light_dir())[0]);
    }
}
