//! Scene generators: large layouts from a few parameters, so benchmark scenes stay small files.

use crate::body_desc::{BodyDesc, MassSpec};
use jostle_collide::{Material, ShapeDesc};
use jostle_math::Vec3;
use serde::{Deserialize, Serialize};

fn half() -> f32 {
    0.5
}
fn friction() -> f32 {
    0.6
}
fn density() -> f32 {
    1000.0
}

/// A generator of bodies (`generators: [Pyramid(rows: 20), ...]`). All boxes are cuboids named
/// `<name>-<i>` in generation order, resting exactly on y = `origin.y` (no initial overlap).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Generator {
    /// A 2D pyramid in the XY plane: `rows` boxes at the bottom, one fewer in each row above
    /// (rows·(rows+1)/2 boxes).
    Pyramid {
        /// Rows (bottom row has this many boxes).
        rows: u32,
        /// Half the box size (m). Default 0.5 (1 m boxes).
        #[serde(default = "half")]
        half_extent: f32,
        /// Horizontal gap between neighbouring boxes (m). Default 0.
        #[serde(default)]
        gap: f32,
        /// Centre of the bottom row's base (m).
        #[serde(default)]
        origin: Vec3,
        /// Friction. Default 0.6.
        #[serde(default = "friction")]
        friction: f32,
        /// Density (kg/m³). Default 1000.
        #[serde(default = "density")]
        density: f32,
        /// Density of the top box (kg/m³), for mass-ratio scenes. Default: `density`.
        #[serde(default)]
        top_density: Option<f32>,
        /// Name prefix. Default "pyramid".
        #[serde(default)]
        name: Option<String>,
    },
    /// A 3D pyramid of square layers: `layers`² boxes at the bottom, (layers−1)² above, …
    /// (layers·(layers+1)·(2·layers+1)/6 boxes: 385 for 10 layers).
    Pyramid3D {
        /// Layers.
        layers: u32,
        /// Half the box size (m). Default 0.5.
        #[serde(default = "half")]
        half_extent: f32,
        /// Centre of the bottom layer's base (m).
        #[serde(default)]
        origin: Vec3,
        /// Friction. Default 0.6.
        #[serde(default = "friction")]
        friction: f32,
        /// Density (kg/m³). Default 1000.
        #[serde(default = "density")]
        density: f32,
        /// Name prefix. Default "pyramid3d".
        #[serde(default)]
        name: Option<String>,
    },
    /// A vertical stack of `count` boxes.
    Stack {
        /// Boxes.
        count: u32,
        /// Half extents of each box (m). Default (0.5, 0.5, 0.5).
        #[serde(default = "half_extents")]
        half_extents: Vec3,
        /// Centre of the bottom box's base (m).
        #[serde(default)]
        origin: Vec3,
        /// Friction. Default 0.6.
        #[serde(default = "friction")]
        friction: f32,
        /// Density (kg/m³). Default 1000.
        #[serde(default = "density")]
        density: f32,
        /// Density of the top box (kg/m³), for heavy-on-light stacks. Default: `density`.
        #[serde(default)]
        top_density: Option<f32>,
        /// Name prefix. Default "stack".
        #[serde(default)]
        name: Option<String>,
    },
    /// A brick wall in the XY plane, `columns` bricks long and `rows` high, in running bond:
    /// every other row is offset by half a brick and closed at both ends with a half brick
    /// (`columns` − 1 whole bricks and two halves), so both ends of the wall are flush and no
    /// brick overhangs the row below.
    Wall {
        /// Bricks per row.
        columns: u32,
        /// Rows.
        rows: u32,
        /// Half extents of a brick (m). Default (0.5, 0.25, 0.25).
        #[serde(default = "brick")]
        half_extents: Vec3,
        /// Centre of the bottom row's base (m).
        #[serde(default)]
        origin: Vec3,
        /// Friction. Default 0.6.
        #[serde(default = "friction")]
        friction: f32,
        /// Density (kg/m³). Default 1000.
        #[serde(default = "density")]
        density: f32,
        /// Name prefix. Default "wall".
        #[serde(default)]
        name: Option<String>,
    },
    /// A grid of separate piles: `nx`·`nz` stacks of `height` boxes, `spacing` apart.
    Piles {
        /// Piles along X.
        nx: u32,
        /// Piles along Z.
        nz: u32,
        /// Boxes per pile.
        height: u32,
        /// Distance between pile centres (m). Default 3.
        #[serde(default = "spacing")]
        spacing: f32,
        /// Half the box size (m). Default 0.5.
        #[serde(default = "half")]
        half_extent: f32,
        /// Centre of the grid's base (m).
        #[serde(default)]
        origin: Vec3,
        /// Friction. Default 0.6.
        #[serde(default = "friction")]
        friction: f32,
        /// Density (kg/m³). Default 1000.
        #[serde(default = "density")]
        density: f32,
        /// Name prefix. Default "pile".
        #[serde(default)]
        name: Option<String>,
    },
}

fn half_extents() -> Vec3 {
    Vec3::splat(0.5)
}
fn brick() -> Vec3 {
    Vec3::new(0.5, 0.25, 0.25)
}
fn spacing() -> f32 {
    3.0
}

fn cuboid(name: String, h: Vec3, centre: Vec3, friction: f32, density: f32) -> BodyDesc {
    let mut d = BodyDesc::dynamic(name, ShapeDesc::Cuboid { half_extents: h }).at(centre);
    d.mass = MassSpec::Density(density);
    d.material = Material::new(friction, 0.0);
    d
}

impl Generator {
    /// The most bodies one generator may make, and a scene's generators and bodies together
    /// ([`super::Scene::validate`]): beyond it a scene would exhaust memory (the generators'
    /// counts multiply: `Piles(nx: 100000, nz: 100000, height: 100000)` is 10¹⁵ boxes) before
    /// its first step.
    pub const MAX_BODIES: u64 = 1_000_000;

    /// How many bodies [`Generator::bodies`] makes (for `Wall`, at most this many: a running
    /// bond's rows alternate between `columns` bricks and `columns − 1` plus two halves).
    pub fn body_count(&self) -> u64 {
        match self {
            Self::Pyramid { rows, .. } => {
                let r = u64::from(*rows);
                r * (r + 1) / 2
            }
            Self::Pyramid3D { layers, .. } => {
                let l = u64::from(*layers);
                l * (l + 1) * (2 * l + 1) / 6
            }
            Self::Stack { count, .. } => u64::from(*count),
            Self::Wall { columns, rows, .. } => {
                u64::from(*rows).saturating_mul(u64::from(*columns) + 1)
            }
            Self::Piles { nx, nz, height, .. } => u64::from(*nx)
                .saturating_mul(u64::from(*nz))
                .saturating_mul(u64::from(*height)),
        }
    }

    /// Checks the parameters, and that the generator makes at most [`Generator::MAX_BODIES`]
    /// bodies; the error is (field, message).
    pub fn validate(&self) -> Result<(), (String, String)> {
        self.validate_parameters()?;
        let n = self.body_count();
        if n > Self::MAX_BODIES {
            // The field that sets the count (`Pyramid(rows: 100000)` was reported as
            // `count`, which a pyramid does not have).
            let field = match self {
                Self::Pyramid { .. } => "rows",
                Self::Pyramid3D { .. } => "layers",
                Self::Stack { .. } => "count",
                Self::Wall { .. } => "columns",
                Self::Piles { .. } => "nx",
            };
            return Err((
                field.into(),
                format!(
                    "makes {n} bodies, more than the {} one generator may make",
                    Self::MAX_BODIES
                ),
            ));
        }
        Ok(())
    }

    fn validate_parameters(&self) -> Result<(), (String, String)> {
        let positive = |field: &str, x: f32| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err((
                    field.to_string(),
                    format!("must be finite and > 0, got {x}"),
                ))
            }
        };
        // A density the bodies would refuse, named as the generator's field (it was reported
        // as the first generated body's).
        let density_ok = |field: &str, d: f32| {
            positive(field, d)?;
            if d > crate::MAX_DENSITY {
                return Err((
                    field.to_string(),
                    format!(
                        "{d:e} kg/m³ is above the limit of {:e} kg/m³",
                        crate::MAX_DENSITY
                    ),
                ));
            }
            Ok(())
        };
        let count = |field: &str, n: u32| {
            if (1..=100_000).contains(&n) {
                Ok(())
            } else {
                Err((field.to_string(), format!("must be in 1..=100000, got {n}")))
            }
        };
        let common = |origin: &Vec3, friction: f32, density: f32| {
            if !origin.is_finite() {
                return Err((
                    "origin".to_string(),
                    format!("must be finite, got {origin}"),
                ));
            }
            if !(friction.is_finite() && friction >= 0.0) {
                return Err((
                    "friction".to_string(),
                    format!("must be finite and >= 0, got {friction}"),
                ));
            }
            density_ok("density", density)
        };
        match self {
            Self::Pyramid {
                rows,
                half_extent,
                gap,
                origin,
                friction,
                density,
                top_density,
                ..
            } => {
                count("rows", *rows)?;
                positive("half_extent", *half_extent)?;
                if !(gap.is_finite() && *gap >= 0.0) {
                    return Err(("gap".into(), format!("must be finite and >= 0, got {gap}")));
                }
                if let Some(t) = top_density {
                    density_ok("top_density", *t)?;
                }
                common(origin, *friction, *density)
            }
            Self::Pyramid3D {
                layers,
                half_extent,
                origin,
                friction,
                density,
                ..
            } => {
                count("layers", *layers)?;
                positive("half_extent", *half_extent)?;
                common(origin, *friction, *density)
            }
            Self::Stack {
                count: n,
                half_extents,
                origin,
                friction,
                density,
                top_density,
                ..
            } => {
                count("count", *n)?;
                if let Some(t) = top_density {
                    density_ok("top_density", *t)?;
                }
                if !(half_extents.is_finite() && half_extents.min_element() > 0.0) {
                    return Err((
                        "half_extents".into(),
                        format!("must be finite and > 0, got {half_extents}"),
                    ));
                }
                common(origin, *friction, *density)
            }
            Self::Wall {
                columns,
                rows,
                half_extents,
                origin,
                friction,
                density,
                ..
            } => {
                count("columns", *columns)?;
                count("rows", *rows)?;
                if !(half_extents.is_finite() && half_extents.min_element() > 0.0) {
                    return Err((
                        "half_extents".into(),
                        format!("must be finite and > 0, got {half_extents}"),
                    ));
                }
                common(origin, *friction, *density)
            }
            Self::Piles {
                nx,
                nz,
                height,
                spacing,
                half_extent,
                origin,
                friction,
                density,
                ..
            } => {
                count("nx", *nx)?;
                count("nz", *nz)?;
                count("height", *height)?;
                positive("spacing", *spacing)?;
                positive("half_extent", *half_extent)?;
                common(origin, *friction, *density)
            }
        }
    }

    /// The bodies this generator makes, in a fixed order (bottom to top, −X to +X, −Z to +Z).
    pub fn bodies(&self) -> Vec<BodyDesc> {
        let mut out = Vec::new();
        match self {
            Self::Pyramid {
                rows,
                half_extent: h,
                gap,
                origin,
                friction,
                density,
                top_density,
                name,
            } => {
                let name = name.as_deref().unwrap_or("pyramid");
                let pitch = 2.0 * h + gap;
                for row in 0..*rows {
                    let n = rows - row;
                    for i in 0..n {
                        let x = (i as f32 - (n - 1) as f32 / 2.0) * pitch;
                        let y = h + 2.0 * h * row as f32;
                        let d = if n == 1 {
                            top_density.unwrap_or(*density)
                        } else {
                            *density
                        };
                        let centre = *origin + Vec3::new(x, y, 0.0);
                        out.push(cuboid(
                            format!("{name}-{}", out.len()),
                            Vec3::splat(*h),
                            centre,
                            *friction,
                            d,
                        ));
                    }
                }
            }
            Self::Pyramid3D {
                layers,
                half_extent: h,
                origin,
                friction,
                density,
                name,
            } => {
                let name = name.as_deref().unwrap_or("pyramid3d");
                for layer in 0..*layers {
                    let n = layers - layer;
                    for i in 0..n {
                        for k in 0..n {
                            let off = |j: u32| (j as f32 - (n - 1) as f32 / 2.0) * 2.0 * h;
                            let centre =
                                *origin + Vec3::new(off(i), h + 2.0 * h * layer as f32, off(k));
                            out.push(cuboid(
                                format!("{name}-{}", out.len()),
                                Vec3::splat(*h),
                                centre,
                                *friction,
                                *density,
                            ));
                        }
                    }
                }
            }
            Self::Stack {
                count,
                half_extents: he,
                origin,
                friction,
                density,
                top_density,
                name,
            } => {
                let name = name.as_deref().unwrap_or("stack");
                for i in 0..*count {
                    let centre = *origin + Vec3::new(0.0, he.y * (2 * i + 1) as f32, 0.0);
                    let d = if i + 1 == *count {
                        top_density.unwrap_or(*density)
                    } else {
                        *density
                    };
                    out.push(cuboid(format!("{name}-{i}"), *he, centre, *friction, d));
                }
            }
            Self::Wall {
                columns,
                rows,
                half_extents: he,
                origin,
                friction,
                density,
                name,
            } => {
                let name = name.as_deref().unwrap_or("wall");
                // The wall spans x in ±columns·he.x about the origin.
                let left = -(*columns as f32) * he.x;
                for row in 0..*rows {
                    let y = he.y * (2 * row + 1) as f32;
                    let mut brick = |x: f32, half: Vec3| {
                        out.push(cuboid(
                            format!("{name}-{}", out.len()),
                            half,
                            *origin + Vec3::new(x, y, 0.0),
                            *friction,
                            *density,
                        ));
                    };
                    if row % 2 == 0 {
                        for c in 0..*columns {
                            brick(left + (2 * c + 1) as f32 * he.x, *he);
                        }
                    } else {
                        let half = Vec3::new(0.5 * he.x, he.y, he.z);
                        brick(left + 0.5 * he.x, half);
                        for c in 1..*columns {
                            brick(left + (2 * c) as f32 * he.x, *he);
                        }
                        brick(-left - 0.5 * he.x, half);
                    }
                }
            }
            Self::Piles {
                nx,
                nz,
                height,
                spacing,
                half_extent: h,
                origin,
                friction,
                density,
                name,
            } => {
                let name = name.as_deref().unwrap_or("pile");
                for ix in 0..*nx {
                    for iz in 0..*nz {
                        let x = (ix as f32 - (*nx - 1) as f32 / 2.0) * spacing;
                        let z = (iz as f32 - (*nz - 1) as f32 / 2.0) * spacing;
                        for k in 0..*height {
                            let centre = *origin + Vec3::new(x, h * (2 * k + 1) as f32, z);
                            out.push(cuboid(
                                format!("{name}-{}", out.len()),
                                Vec3::splat(*h),
                                centre,
                                *friction,
                                *density,
                            ));
                        }
                    }
                }
            }
        }
        out
    }
}
