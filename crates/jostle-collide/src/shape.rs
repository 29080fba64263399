//! Shape descriptions: the plain, serializable form of a collision shape, and its validated
//! conversion into a parry [`SharedShape`].
//!
//! In: a [`ShapeDesc`] from a scene file or from code. Out: a `SharedShape`, or a
//! [`ShapeError`] naming the offending field. Validation happens here, before parry sees the
//! numbers, because parry asserts (panics) or silently produces NaN on some bad inputs
//! (an empty compound, a nested compound, an out-of-range mesh index, a zero normal).
//! Nothing here knows about bodies or contacts.

use jostle_math::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::{SharedShape, TriMeshFlags};
use thiserror::Error;

/// Why a shape description (or its mass properties) was rejected.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum ShapeError {
    /// A field holds a value the shape cannot be built from (non-finite, non-positive,
    /// zero-length, empty, out of range or degenerate).
    #[error("invalid `{field}`: {message}")]
    Invalid {
        /// Path of the offending field, e.g. `radius`, `half_extents`, `parts[2].radius`.
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// The shape encloses no finite volume (a half-space or a triangle mesh), so it has no mass
    /// properties: it may only be attached to a fixed body.
    #[error("a {shape} cannot be dynamic: it encloses no finite volume; attach it to a fixed body")]
    NotDynamic {
        /// The shape's kind, as [`ShapeDesc::kind`] names it.
        shape: &'static str,
    },
}

impl ShapeError {
    /// The offending field: `radius`, `half_extents`, `half_height`, `normal`, `points`,
    /// `vertices`, `indices`, `parts`, `density`... prefixed by `parts[i].` inside a compound.
    /// `shape` for [`ShapeError::NotDynamic`].
    pub fn field(&self) -> &str {
        match self {
            Self::Invalid { field, .. } => field,
            Self::NotDynamic { .. } => "shape",
        }
    }

    /// The human-readable reason.
    pub fn message(&self) -> String {
        match self {
            Self::Invalid { message, .. } => message.clone(),
            Self::NotDynamic { .. } => self.to_string(),
        }
    }

    pub(crate) fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    fn in_part(self, index: usize) -> Self {
        match self {
            Self::Invalid { field, message } => Self::Invalid {
                field: format!("parts[{index}].{field}"),
                message,
            },
            other => other,
        }
    }
}

/// One part of a [`ShapeDesc::Compound`]: a convex shape placed in the compound's frame.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct CompoundPart {
    /// The part's shape: a ball, cuboid, capsule, cylinder or convex hull (no half-space,
    /// mesh or nested compound).
    pub shape: ShapeDesc,
    /// Position of the part's origin in the compound's frame (m). Default (in scene files):
    /// the compound's origin.
    #[cfg_attr(feature = "serde", serde(default))]
    pub position: Vec3,
    /// Orientation of the part in the compound's frame (normalized on build). Default (in
    /// scene files): the compound's own, the identity (`Quat`'s default).
    #[cfg_attr(feature = "serde", serde(default))]
    pub rotation: Quat,
}

/// A collision shape, described by plain numbers (SI units, shape's own frame).
///
/// Capsules and cylinders run along +Y. Build it into a parry shape with [`ShapeDesc::build`],
/// which validates every field.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub enum ShapeDesc {
    /// A sphere centred on the origin.
    Ball {
        /// Radius (m), > 0.
        radius: f32,
    },
    /// A box centred on the origin, aligned with the axes.
    Cuboid {
        /// Half the size along each axis (m), each > 0.
        half_extents: Vec3,
    },
    /// A capsule along +Y: a segment from −half_height to +half_height, inflated by `radius`.
    Capsule {
        /// Half the length of the inner segment (m), > 0.
        half_height: f32,
        /// Radius (m), > 0.
        radius: f32,
    },
    /// A cylinder along +Y, centred on the origin.
    Cylinder {
        /// Half the height (m), > 0.
        half_height: f32,
        /// Radius (m), > 0.
        radius: f32,
    },
    /// The convex hull of a point cloud (at least 4 points not all in one plane).
    ConvexHull {
        /// The points (m).
        points: Vec<Vec3>,
    },
    /// The half-space below the plane through the origin with the given outward normal: the
    /// normal points to the free side. Unbounded: only valid on fixed bodies.
    HalfSpace {
        /// Outward normal (normalized on build), non-zero.
        normal: Vec3,
    },
    /// A triangle mesh (a surface, no volume): only valid on fixed bodies. One-sided: each
    /// triangle's solid side is behind the face from which its vertices run counter-clockwise.
    TriMesh {
        /// Vertex positions (m).
        vertices: Vec<Vec3>,
        /// Triangles as vertex indices; none may be out of range or degenerate.
        indices: Vec<[u32; 3]>,
    },
    /// Several convex parts rigidly joined.
    Compound {
        /// The parts, at least one.
        parts: Vec<CompoundPart>,
    },
}

impl ShapeDesc {
    /// The shape's kind in lower case (`"ball"`, `"cuboid"`, `"half-space"`...), for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Ball { .. } => "ball",
            Self::Cuboid { .. } => "cuboid",
            Self::Capsule { .. } => "capsule",
            Self::Cylinder { .. } => "cylinder",
            Self::ConvexHull { .. } => "convex hull",
            Self::HalfSpace { .. } => "half-space",
            Self::TriMesh { .. } => "triangle mesh",
            Self::Compound { .. } => "compound",
        }
    }

    /// Whether the shape extends to infinity (a half-space): it has no bounding box.
    pub fn is_unbounded(&self) -> bool {
        matches!(self, Self::HalfSpace { .. })
    }

    /// Whether the shape encloses a finite volume, i.e. may be attached to a dynamic body.
    pub fn can_be_dynamic(&self) -> bool {
        !matches!(self, Self::HalfSpace { .. } | Self::TriMesh { .. })
    }

    /// Validates the description and builds the parry shape.
    ///
    /// Errors name the offending field: non-finite numbers, non-positive sizes, a zero normal,
    /// fewer than 4 or coplanar hull points, an empty mesh, an out-of-range index or a
    /// degenerate triangle, an empty compound or a compound part that is not a bounded convex
    /// shape. Never panics.
    pub fn build(&self) -> Result<SharedShape, ShapeError> {
        let shape = self.build_unbounded_size()?;
        if !matches!(self, Self::HalfSpace { .. }) {
            let aabb = shape.compute_local_aabb();
            let reach = aabb.mins.abs().max(aabb.maxs.abs()).max_element();
            if reach.is_nan() || reach > MAX_EXTENT {
                return Err(ShapeError::invalid(
                    "size",
                    format!(
                        "the {} reaches {reach:.3e} m from its origin, beyond the limit of \
                         {MAX_EXTENT:e} m",
                        self.kind()
                    ),
                ));
            }
        }
        Ok(shape)
    }

    fn build_unbounded_size(&self) -> Result<SharedShape, ShapeError> {
        match self {
            Self::Ball { radius } => {
                positive("radius", *radius)?;
                Ok(SharedShape::ball(*radius))
            }
            Self::Cuboid { half_extents: h } => {
                if !(h.is_finite() && h.min_element() > 0.0) {
                    return Err(ShapeError::invalid(
                        "half_extents",
                        format!("every half extent must be finite and > 0, got {h}"),
                    ));
                }
                Ok(SharedShape::cuboid(h.x, h.y, h.z))
            }
            Self::Capsule {
                half_height,
                radius,
            } => {
                positive("half_height", *half_height)?;
                positive("radius", *radius)?;
                Ok(SharedShape::capsule_y(*half_height, *radius))
            }
            Self::Cylinder {
                half_height,
                radius,
            } => {
                positive("half_height", *half_height)?;
                positive("radius", *radius)?;
                Ok(SharedShape::cylinder(*half_height, *radius))
            }
            Self::ConvexHull { points } => build_hull(points),
            Self::HalfSpace { normal } => {
                let unit = (normal.is_finite())
                    .then(|| normal.try_normalize())
                    .flatten();
                let unit = unit.ok_or_else(|| {
                    ShapeError::invalid(
                        "normal",
                        format!("must be finite and non-zero, got {normal}"),
                    )
                })?;
                Ok(SharedShape::halfspace(unit))
            }
            Self::TriMesh { vertices, indices } => build_trimesh(vertices, indices),
            Self::Compound { parts } => build_compound(parts),
        }
    }
}

/// How far (m) a shape may reach from its origin: 10⁶ m, where f32 still resolves 6 cm;
/// beyond it contacts are rounding noise (a snapshot's `half_extents: (0.5, 0.5, 1e30)` went
/// non-finite at the first step).
pub const MAX_EXTENT: f32 = 1.0e6;

fn positive(field: &'static str, value: f32) -> Result<(), ShapeError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ShapeError::invalid(
            field,
            format!("must be finite and > 0, got {value}"),
        ))
    }
}

fn all_finite(field: &'static str, points: &[Vec3]) -> Result<(), ShapeError> {
    match points.iter().position(|p| !p.is_finite()) {
        None => Ok(()),
        Some(i) => Err(ShapeError::invalid(
            field,
            format!("{field}[{i}] = {} is not finite", points[i]),
        )),
    }
}

/// The points' largest extent along any axis: the scale that degeneracy thresholds follow.
fn extent(points: &[Vec3]) -> f32 {
    let (lo, hi) = points.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    (hi - lo).max_element()
}

/// Whether the cloud spans a volume: some tetrahedron of its points has a volume above a
/// tolerance relative to its size. Checked before parry's hull builder, which may otherwise
/// fail or produce a flat polyhedron with no interior.
fn spans_volume(points: &[Vec3]) -> bool {
    let size = extent(points);
    if size.is_nan() || size <= 0.0 {
        return false;
    }
    let tol = 1e-6 * size;
    let a = points[0];
    // Farthest point from a, then farthest from the line ab, then farthest from plane abc.
    let b = *points
        .iter()
        .max_by(|p, q| p.distance_squared(a).total_cmp(&q.distance_squared(a)))
        .unwrap_or(&a);
    let ab = b - a;
    if ab.length() <= tol {
        return false;
    }
    let c = *points
        .iter()
        .max_by(|p, q| {
            ab.cross(**p - a)
                .length_squared()
                .total_cmp(&ab.cross(**q - a).length_squared())
        })
        .unwrap_or(&a);
    let n = ab.cross(c - a);
    if n.length() <= tol * ab.length() {
        return false;
    }
    let n = n.normalize();
    points.iter().any(|p| (*p - a).dot(n).abs() > tol)
}

fn build_hull(points: &[Vec3]) -> Result<SharedShape, ShapeError> {
    if points.len() < 4 {
        return Err(ShapeError::invalid(
            "points",
            format!(
                "a convex hull needs at least 4 points, got {}",
                points.len()
            ),
        ));
    }
    all_finite("points", points)?;
    if !spans_volume(points) {
        return Err(ShapeError::invalid(
            "points",
            format!(
                "the points are coplanar or collinear, or the hull is thinner than 10⁻⁶ of its \
                 extent ({} m): it has no volume",
                extent(points)
            ),
        ));
    }
    SharedShape::convex_hull(points)
        .ok_or_else(|| ShapeError::invalid("points", "the convex hull of the points is degenerate"))
}

fn build_trimesh(vertices: &[Vec3], indices: &[[u32; 3]]) -> Result<SharedShape, ShapeError> {
    if vertices.is_empty() {
        return Err(ShapeError::invalid(
            "vertices",
            "a triangle mesh needs vertices",
        ));
    }
    if indices.is_empty() {
        return Err(ShapeError::invalid(
            "indices",
            "a triangle mesh needs at least one triangle",
        ));
    }
    all_finite("vertices", vertices)?;
    let tol = 1e-12 * extent(vertices).powi(2);
    for (t, tri) in indices.iter().enumerate() {
        if let Some(&i) = tri.iter().find(|&&i| i as usize >= vertices.len()) {
            return Err(ShapeError::invalid(
                "indices",
                format!(
                    "triangle {t} uses vertex {i}, but there are {} vertices",
                    vertices.len()
                ),
            ));
        }
        let [a, b, c] = tri.map(|i| vertices[i as usize]);
        if (b - a).cross(c - a).length() <= tol {
            return Err(ShapeError::invalid(
                "indices",
                format!("triangle {t} is degenerate (zero area)"),
            ));
        }
    }
    // FIX_INTERNAL_EDGES gives parry the mesh's pseudo-normals, so a body sliding across the
    // shared edge of two coplanar triangles gets the face normal, not a tilted edge normal
    // (the "internal edge" bump). It makes the mesh one-sided: triangles face the side from
    // which their vertices run counter-clockwise.
    SharedShape::trimesh_with_flags(
        vertices.to_vec(),
        indices.to_vec(),
        TriMeshFlags::FIX_INTERNAL_EDGES,
    )
    .map_err(|e| ShapeError::invalid("indices", format!("parry rejected the mesh: {e}")))
}

fn build_compound(parts: &[CompoundPart]) -> Result<SharedShape, ShapeError> {
    if parts.is_empty() {
        return Err(ShapeError::invalid(
            "parts",
            "a compound needs at least one part",
        ));
    }
    let mut built = Vec::with_capacity(parts.len());
    for (i, part) in parts.iter().enumerate() {
        if !part.shape.can_be_dynamic() || matches!(part.shape, ShapeDesc::Compound { .. }) {
            return Err(ShapeError::invalid(
                format!("parts[{i}].shape"),
                format!(
                    "a compound part must be a bounded convex shape, got a {}",
                    part.shape.kind()
                ),
            ));
        }
        if !part.position.is_finite() {
            return Err(ShapeError::invalid(
                format!("parts[{i}].position"),
                "must be finite",
            ));
        }
        let rotation = part
            .rotation
            .is_finite()
            .then(|| part.rotation.try_normalize_quat())
            .flatten()
            .ok_or_else(|| {
                ShapeError::invalid(
                    format!("parts[{i}].rotation"),
                    "must be a finite, non-zero quaternion",
                )
            })?;
        let shape = part.shape.build().map_err(|e| e.in_part(i))?;
        built.push((Pose::from_parts(part.position, rotation), shape));
    }
    Ok(SharedShape::compound(built))
}

/// `Quat::try_normalize` is not in glam 0.33; this is its quaternion spelling.
trait TryNormalizeQuat: Sized {
    fn try_normalize_quat(self) -> Option<Self>;
}

impl TryNormalizeQuat for Quat {
    fn try_normalize_quat(self) -> Option<Self> {
        let len = self.length();
        (len.is_finite() && len > 1e-6).then(|| self / len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_field() {
        let cases = [
            (ShapeDesc::Ball { radius: 0.0 }, "radius"),
            (ShapeDesc::Ball { radius: f32::NAN }, "radius"),
            (
                ShapeDesc::Cuboid {
                    half_extents: Vec3::new(1.0, -1.0, 1.0),
                },
                "half_extents",
            ),
            (
                ShapeDesc::Capsule {
                    half_height: f32::INFINITY,
                    radius: 1.0,
                },
                "half_height",
            ),
            (
                ShapeDesc::Cylinder {
                    half_height: 1.0,
                    radius: 0.0,
                },
                "radius",
            ),
            (ShapeDesc::HalfSpace { normal: Vec3::ZERO }, "normal"),
            (ShapeDesc::ConvexHull { points: vec![] }, "points"),
            (
                ShapeDesc::ConvexHull {
                    points: vec![
                        Vec3::ZERO,
                        Vec3::X,
                        Vec3::Z,
                        Vec3::new(1.0, 0.0, 1.0),
                        Vec3::splat(0.5) * Vec3::new(1.0, 0.0, 1.0),
                    ],
                },
                "points",
            ),
            (
                ShapeDesc::TriMesh {
                    vertices: vec![],
                    indices: vec![[0, 1, 2]],
                },
                "vertices",
            ),
            (
                ShapeDesc::TriMesh {
                    vertices: vec![Vec3::ZERO, Vec3::X, Vec3::Z],
                    indices: vec![],
                },
                "indices",
            ),
            (
                ShapeDesc::TriMesh {
                    vertices: vec![Vec3::ZERO, Vec3::X, Vec3::Z],
                    indices: vec![[0, 1, 3]],
                },
                "indices",
            ),
            (
                ShapeDesc::TriMesh {
                    vertices: vec![Vec3::ZERO, Vec3::X, Vec3::Z],
                    indices: vec![[0, 1, 1]],
                },
                "indices",
            ),
            (ShapeDesc::Compound { parts: vec![] }, "parts"),
        ];
        for (desc, field) in cases {
            let err = desc
                .build()
                .expect_err(&format!("{desc:?} must be rejected"));
            assert_eq!(err.field(), field, "{desc:?}: {err}");
        }
    }

    #[test]
    fn compound_errors_carry_the_part_path() {
        let part = |shape| CompoundPart {
            shape,
            position: Vec3::ZERO,
            rotation: Quat::IDENTITY,
        };
        let bad_radius = ShapeDesc::Compound {
            parts: vec![
                part(ShapeDesc::Ball { radius: 1.0 }),
                part(ShapeDesc::Ball { radius: -1.0 }),
            ],
        };
        assert_eq!(bad_radius.build().unwrap_err().field(), "parts[1].radius");
        let nested = ShapeDesc::Compound {
            parts: vec![part(bad_radius.clone())],
        };
        assert_eq!(nested.build().unwrap_err().field(), "parts[0].shape");
        let plane = ShapeDesc::Compound {
            parts: vec![part(ShapeDesc::HalfSpace { normal: Vec3::Y })],
        };
        assert_eq!(plane.build().unwrap_err().field(), "parts[0].shape");
        let zero_rot = ShapeDesc::Compound {
            parts: vec![CompoundPart {
                shape: ShapeDesc::Ball { radius: 1.0 },
                position: Vec3::ZERO,
                rotation: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0),
            }],
        };
        assert_eq!(zero_rot.build().unwrap_err().field(), "parts[0].rotation");
    }

    #[test]
    fn valid_shapes_build() {
        let cube: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32))
            .collect();
        let descs = [
            ShapeDesc::Ball { radius: 0.5 },
            ShapeDesc::Cuboid {
                half_extents: Vec3::new(1.0, 2.0, 3.0),
            },
            ShapeDesc::Capsule {
                half_height: 0.5,
                radius: 0.2,
            },
            ShapeDesc::Cylinder {
                half_height: 0.5,
                radius: 0.2,
            },
            ShapeDesc::ConvexHull { points: cube },
            ShapeDesc::HalfSpace {
                normal: Vec3::new(0.0, 2.0, 0.0),
            },
            ShapeDesc::TriMesh {
                vertices: vec![Vec3::ZERO, Vec3::X, Vec3::Z],
                indices: vec![[0, 2, 1]],
            },
            ShapeDesc::Compound {
                parts: vec![CompoundPart {
                    shape: ShapeDesc::Ball { radius: 1.0 },
                    position: Vec3::X,
                    rotation: Quat::from_rotation_y(0.3) * 2.0,
                }],
            },
        ];
        for d in descs {
            assert!(d.build().is_ok(), "{d:?}");
        }
        let plane = ShapeDesc::HalfSpace {
            normal: Vec3::new(0.0, 2.0, 0.0),
        }
        .build()
        .unwrap();
        assert_eq!(plane.as_halfspace().unwrap().normal, Vec3::Y);
        assert!(ShapeDesc::HalfSpace { normal: Vec3::Y }.is_unbounded());
        assert!(!ShapeDesc::Ball { radius: 1.0 }.is_unbounded());
    }
}
