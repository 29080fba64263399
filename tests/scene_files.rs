//! Scene files: the documented example loads exactly as written, defaults are the documented
//! ones, and every kind of bad input gets an error naming file and line/column or body and
//! field — never a panic.

use jostle::scene::{Scene, SceneError};
use jostle::{ShapeDesc, Vec3};

const BOX_DROP: &str = include_str!("../assets/box_drop.ron");

#[test]
fn box_drop_loads_exactly_as_written() {
    let scene = Scene::parse(BOX_DROP, "box_drop.ron").unwrap();
    assert_eq!(scene.name, "box drop");
    assert_eq!(scene.gravity, Vec3::new(0.0, -9.81, 0.0));
    assert_eq!(scene.dt, 0.016666668);
    assert_eq!(scene.steps, 300);
    assert_eq!(scene.bodies.len(), 2);
    let ground = &scene.bodies[0];
    assert!(ground.fixed);
    assert_eq!(ground.friction, 0.9);
    assert_eq!(ground.shape, ShapeDesc::HalfSpace { normal: Vec3::Y });
    let b = &scene.bodies[1];
    assert_eq!(b.name, "box");
    assert_eq!(b.mass, Some(8.0));
    assert_eq!(b.restitution, 0.6);
    assert_eq!(b.position, Vec3::new(0.0, 3.0, 0.0));
    let world = scene.build().unwrap();
    let h = world.find_body("box").unwrap();
    assert_eq!(world.body(h).unwrap().mass(), 8.0);
}

/// A file that starts with a byte-order mark (as editors on Windows save it) loads as without
/// one (it was refused as "Expected opening `(`" at 1:1), and nesting too deep for the parser
/// is named as such, without advice about the parser's own API (ron's message suggested
/// `ron::Options::recursion_limit` and `serde_stacker`).
#[test]
fn a_byte_order_mark_loads_and_deep_nesting_is_named() {
    let with_bom = format!("\u{feff}{BOX_DROP}");
    let scene = Scene::parse(&with_bom, "bom.ron").expect("a byte-order mark is skipped");
    assert_eq!(scene.name, "box drop");
    let part = |inner: String| format!("Compound(parts: [CompoundPart(shape: {inner})])");
    let mut shape = "Ball(radius: 0.5)".to_string();
    for _ in 0..200 {
        shape = part(shape);
    }
    let text = format!("Scene(bodies: [Body(name: \"deep\", shape: {shape})])");
    let e = Scene::parse(&text, "deep.ron").unwrap_err().to_string();
    assert!(
        e.contains("nested too deeply") && !e.contains("serde_stacker"),
        "{e}"
    );
}

#[test]
fn defaults_are_the_documented_ones() {
    let scene = Scene::parse("Scene(bodies: [Body(shape: Ball(radius: 0.5))])", "t.ron").unwrap();
    assert_eq!(scene.gravity, Vec3::new(0.0, -9.81, 0.0));
    assert_eq!(scene.dt, 1.0 / 60.0);
    assert_eq!(scene.steps, 600);
    let b = &scene.bodies[0];
    assert_eq!(
        (
            b.friction,
            b.restitution,
            b.linear_damping,
            b.angular_damping
        ),
        (0.5, 0.0, 0.0, 0.0)
    );
    assert!(b.can_sleep && !b.fixed);
    assert_eq!(b.position, Vec3::ZERO);
    let world = scene.build().unwrap();
    let (_, _, body) = world.bodies().next().unwrap();
    // Density 1000 kg/m³: a 0.5 m ball weighs 4/3·π·0.125·1000 ≈ 523.6 kg.
    assert!((body.mass() - 523.598_8).abs() < 0.05, "{}", body.mass());
}

/// A compound's parts take the compound's origin and orientation when they give none, as a
/// collider does (both fields were required).
#[test]
fn compound_parts_default_to_the_compound_frame() {
    let scene = Scene::parse(
        "Scene(bodies: [Body(name: \"dumbbell\", shape: Compound(parts: [\
           CompoundPart(shape: Ball(radius: 0.5)),\
           CompoundPart(shape: Ball(radius: 0.5), position: (0.0, 2.0, 0.0))]))])",
        "t.ron",
    )
    .unwrap();
    let world = scene.build().unwrap();
    let (_, _, body) = world.bodies().next().unwrap();
    // Two 0.5 m balls of 523.6 kg, at 0 and 2 m: the centre of mass half-way.
    assert!(
        (body.mass() - 2.0 * 523.598_8).abs() < 0.1,
        "{}",
        body.mass()
    );
    assert!(
        (body.position.y - 1.0).abs() < 1e-4,
        "centre of mass at {}",
        body.position
    );
}

fn error(text: &str) -> SceneError {
    match Scene::parse(text, "bad.ron") {
        Ok(_) => panic!("accepted a bad scene: {text}"),
        Err(e) => e,
    }
}

fn body_field(text: &str) -> (String, String) {
    match error(text) {
        SceneError::Body {
            file,
            error: jostle::BodyError::Field { body, field, .. },
            ..
        } => {
            assert_eq!(file, "bad.ron");
            (body, field)
        }
        other => panic!("expected a body error, got {other}"),
    }
}

#[test]
fn malformed_ron_reports_line_and_column() {
    let e = error(
        "Scene(\n  name: \"x\",\n  bodies: [\n    Body(name: \"a\", shape: Ball(radius: 1.0)\n  ],\n)",
    );
    match &e {
        SceneError::Parse {
            file, line, column, ..
        } => {
            assert_eq!(file, "bad.ron");
            assert_eq!(*line, 5, "{e}");
            assert!(*column > 0);
        }
        other => panic!("{other}"),
    }
    assert!(e.to_string().starts_with("bad.ron:5:"), "{e}");
}

#[test]
fn wrong_types_report_position_and_body() {
    let e = error("Scene(bodies: [\n Body(name: \"crate\",\n shape: Ball(radius: \"big\"))])");
    let SceneError::Parse { line, body, .. } = &e else {
        panic!("{e}")
    };
    assert_eq!(*line, 3);
    assert_eq!(body.as_deref(), Some("crate"), "{e}");
}

#[test]
fn unknown_fields_are_errors_naming_the_body() {
    let e = error("Scene(bodies: [Body(name: \"b1\", shape: Ball(radius: 1.0), colour: 3)])");
    let SceneError::Parse { message, body, .. } = &e else {
        panic!("{e}")
    };
    assert!(message.contains("colour"), "{e}");
    assert_eq!(body.as_deref(), Some("b1"));
    let e = error("Scene(gravity: (0.0, -9.81, 0.0), wind: 3.0)");
    assert!(e.to_string().contains("wind"), "{e}");
}

#[test]
fn missing_shape_is_an_error() {
    let e = error("Scene(bodies: [Body(name: \"ghost\", position: (0.0, 1.0, 0.0))])");
    assert!(e.to_string().contains("shape"), "{e}");
}

#[test]
fn non_finite_numbers_name_body_and_field() {
    let (b, f) = body_field(
        "Scene(bodies: [Body(name: \"n\", shape: Ball(radius: 1.0), position: (0.0, NaN, 0.0))])",
    );
    assert_eq!((b.as_str(), f.as_str()), ("n", "position"));
    let (_, f) = body_field(
        "Scene(bodies: [Body(name: \"n\", shape: Ball(radius: 1.0), linear_velocity: (inf, 0.0, 0.0))])",
    );
    assert_eq!(f, "linear_velocity");
    let (_, f) = body_field("Scene(bodies: [Body(name: \"n\", shape: Ball(radius: inf))])");
    assert_eq!(f, "shape.radius");
    let e = error("Scene(gravity: (0.0, NaN, 0.0))");
    assert!(
        matches!(&e, SceneError::Setting { field, .. } if field == "gravity"),
        "{e}"
    );
}

#[test]
fn non_positive_mass_size_and_density_name_the_field() {
    let (b, f) =
        body_field("Scene(bodies: [Body(name: \"m\", shape: Ball(radius: 1.0), mass: 0.0)])");
    assert_eq!((b.as_str(), f.as_str()), ("m", "mass"));
    let (_, f) =
        body_field("Scene(bodies: [Body(name: \"m\", shape: Ball(radius: 1.0), mass: -2.0)])");
    assert_eq!(f, "mass");
    let (_, f) =
        body_field("Scene(bodies: [Body(name: \"d\", shape: Ball(radius: 1.0), density: -1.0)])");
    assert_eq!(f, "density");
    let (_, f) = body_field("Scene(bodies: [Body(name: \"s\", shape: Ball(radius: 0.0))])");
    assert_eq!(f, "shape.radius");
    let (_, f) = body_field(
        "Scene(bodies: [Body(name: \"s\", shape: Cuboid(half_extents: (1.0, -1.0, 1.0)))])",
    );
    assert_eq!(f, "shape.half_extents");
    let (_, f) = body_field(
        "Scene(bodies: [Body(name: \"s\", shape: Ball(radius: 1.0), mass: 1.0, density: 3.0)])",
    );
    assert_eq!(f, "mass");
    let e = error("Scene(dt: 0.0)");
    assert!(
        matches!(&e, SceneError::Setting { field, .. } if field == "dt"),
        "{e}"
    );
}

#[test]
fn zero_normals_and_bad_meshes_name_the_field() {
    let (b, f) = body_field(
        "Scene(bodies: [Body(name: \"g\", shape: HalfSpace(normal: (0.0, 0.0, 0.0)), fixed: true)])",
    );
    assert_eq!((b.as_str(), f.as_str()), ("g", "shape.normal"));
    let (_, f) = body_field(
        "Scene(bodies: [Body(name: \"t\", shape: TriMesh(vertices: [(0.0,0.0,0.0),(1.0,0.0,0.0),(0.0,0.0,1.0)], indices: [(0, 1, 7)]), fixed: true)])",
    );
    assert_eq!(f, "shape.indices");
    let (_, f) = body_field(
        "Scene(bodies: [Body(name: \"t\", shape: TriMesh(vertices: [], indices: []), fixed: true)])",
    );
    assert!(f == "shape.vertices" || f == "shape.indices", "{f}");
    let (_, f) = body_field(
        "Scene(bodies: [Body(name: \"h\", shape: ConvexHull(points: [(0.0,0.0,0.0),(1.0,0.0,0.0)]))])",
    );
    assert_eq!(f, "shape.points");
    // A half-space cannot be dynamic.
    let (_, f) =
        body_field("Scene(bodies: [Body(name: \"p\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)))])");
    assert_eq!(f, "fixed");
}

#[test]
fn io_errors_name_the_file() {
    let e = Scene::load("does/not/exist.ron").unwrap_err();
    assert!(
        matches!(&e, SceneError::Io { file, .. } if file == "does/not/exist.ron"),
        "{e}"
    );
}

#[test]
fn every_asset_loads_and_builds() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/assets");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "ron") {
            let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
            scene
                .build()
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            n += 1;
        }
    }
    assert!(n >= 2);
}

/// A misspelt field of a kinematic motion is refused like any other (it was ignored: `Turn(...,
/// x: 1)` ran).
#[test]
fn unknown_fields_inside_a_kinematic_motion_are_errors() {
    for (motion, field) in [
        (
            "Turn(center: (0.0, 0.0, 0.0), axis: (0.0, 1.0, 0.0), period: 4.0, x: 1)",
            "`x` in `Turn`",
        ),
        (
            "Line(offset: (1.0, 0.0, 0.0), period: 4.0, perod: 2.0)",
            "`perod` in `Line`",
        ),
    ] {
        let text = format!(
            "Scene(bodies: [Body(name: \"k\", shape: Ball(radius: 0.5), kinematic: {motion})])"
        );
        let e = error(&text).to_string();
        assert!(
            e.contains(field) && e.contains("body \"k\""),
            "{motion}: {e}"
        );
    }
}

#[test]
fn unknown_fields_inside_a_shape_are_errors() {
    let e = error("Scene(bodies: [Body(name: \"s\", shape: Ball(radius: 1.0, colour: 2))])");
    assert!(
        matches!(&e, SceneError::Parse { body: Some(b), message, .. } if b == "s" && message.contains("colour")),
        "{e}"
    );
}

#[test]
fn resolver_settings_load_from_the_scene() {
    use jostle::{MillingtonSettings, ResolverChoice};
    let scene = Scene::parse(
        "Scene(resolver: Millington(velocity_iterations: 64, velocity_epsilon: 0.001))",
        "r.ron",
    )
    .unwrap();
    let Some(ResolverChoice::Millington(s)) = &scene.resolver else {
        panic!("{:?}", scene.resolver)
    };
    assert_eq!(
        s.velocity_iterations.for_contacts(1000),
        64,
        "a plain number is exactly that many picks"
    );
    assert_eq!(s.velocity_epsilon, 0.001);
    assert_eq!(
        s.position_epsilon,
        MillingtonSettings::default().position_epsilon,
        "unset fields keep their defaults"
    );
    let scene = Scene::parse(
        "Scene(resolver: Millington(position_iterations: (per_contact: 2)))",
        "r.ron",
    )
    .unwrap();
    let Some(ResolverChoice::Millington(s)) = &scene.resolver else {
        panic!()
    };
    assert_eq!(s.position_iterations.for_contacts(100), 200);
    let e = Scene::parse(
        "Scene(resolver: Millington(velocity_iteration: 3))",
        "r.ron",
    )
    .unwrap_err();
    assert!(e.to_string().contains("velocity_iteration"), "{e}");
    assert!(Scene::parse("Scene(resolver: Cyclone())", "r.ron").is_err());
}

#[test]
fn generators_that_would_exhaust_memory_are_errors() {
    // Each count is in range, but together they make 10¹⁵ boxes.
    let e = error("Scene(generators: [Piles(nx: 100000, nz: 100000, height: 100000)])");
    let text = e.to_string();
    assert!(
        text.contains("generators[0].nx") && text.contains("1000000000000000 bodies"),
        "{e}"
    );
    // A 100,000-row pyramid is 5·10⁹ boxes, named by its own field (it was `count`, which a
    // pyramid does not have); 1,000 rows (500,500) is fine.
    let e = error("Scene(generators: [Pyramid(rows: 100000)])");
    assert!(e.to_string().contains("generators[0].rows"), "{e}");
    let e = error("Scene(generators: [Pyramid3D(layers: 1000)])");
    assert!(e.to_string().contains("generators[0].layers"), "{e}");
    assert!(Scene::parse("Scene(generators: [Pyramid(rows: 1000)])", "p.ron").is_ok());
    // Within the bound one by one, beyond it together: two of 500,500 boxes.
    let e = error(
        "Scene(generators: [Pyramid(rows: 1000, name: \"a\"), Pyramid(rows: 1000, name: \"b\")])",
    );
    let text = e.to_string();
    assert!(
        text.contains("generators") && text.contains("1001000 bodies"),
        "{e}"
    );
}

#[test]
fn a_generator_density_beyond_the_limit_names_the_generator() {
    // It was reported as the first generated body's field (`body "stack-0": field density`).
    let e = error("Scene(generators: [Stack(count: 3, density: 1e13)])");
    let text = e.to_string();
    assert!(
        text.contains("generators[0].density") && text.contains("above the limit"),
        "{e}"
    );
    let e = error("Scene(generators: [Pyramid(rows: 3, top_density: 1e13)])");
    assert!(e.to_string().contains("generators[0].top_density"), "{e}");
}

#[test]
fn kinematic_paths_beyond_the_limits_name_the_field() {
    // `Line(offset: (1e30, 0, 0))` was accepted and moved its body at 2.8·10³⁰ m/s; a turn
    // once a millisecond about an axis 10⁵ m away, at 6·10⁸ m/s.
    let body = |path: &str| {
        format!("Scene(bodies: [Body(name: \"k\", shape: Ball(radius: 0.5), kinematic: {path})])")
    };
    let cases = [
        (
            "Line(offset: (1e30, 0.0, 0.0), period: 1.0)",
            "kinematic.offset",
        ),
        (
            "Line(offset: (100.0, 0.0, 0.0), period: 1e-4)",
            "kinematic.period",
        ),
        (
            "Turn(center: (1e5, 1.0, 0.0), axis: (0.0, 1.0, 0.0), period: 1e-3)",
            "kinematic.period",
        ),
        (
            "Turn(center: (0.0, 0.0, 0.0), axis: (0.0, 1.0, 0.0), period: 1e-4)",
            "kinematic.period",
        ),
        (
            "Turn(center: (2e6, 0.0, 0.0), axis: (0.0, 1.0, 0.0), period: 1e6)",
            "kinematic.center",
        ),
    ];
    for (path, field) in cases {
        let e = error(&body(path));
        assert!(e.to_string().contains(field), "{path}: {e}");
    }
    // The paddle's turn and a slow line are fine.
    for path in [
        "Turn(center: (0.0, 0.6, 0.0), axis: (0.0, 1.0, 0.0), period: 8.0)",
        "Line(offset: (4.0, 0.0, 0.0), period: 2.0)",
    ] {
        assert!(Scene::parse(&body(path), "k.ron").is_ok(), "{path}");
    }
}

#[test]
fn values_beyond_what_f32_physics_holds_name_the_field_and_the_limit() {
    let message = |text: &str| match error(text) {
        SceneError::Body {
            error: jostle::BodyError::Field { field, message, .. },
            ..
        } => (field, message),
        other => panic!("expected a body error, got {other}"),
    };
    let cases = [
        (
            "linear_velocity: (3e38, 0.0, 0.0)",
            "linear_velocity",
            "1e5 m/s",
        ),
        (
            "linear_velocity: (0.0, 2e5, 0.0)",
            "linear_velocity",
            "1e5 m/s",
        ),
        (
            "angular_velocity: (1e30, 0.0, 0.0)",
            "angular_velocity",
            "1e4 rad/s",
        ),
        ("mass: 1e25", "mass", "1e24 kg"),
        ("density: 1e38", "density", "1e12 kg/m³"),
    ];
    for (fields, field, limit) in cases {
        let (f, m) = message(&format!(
            "Scene(bodies: [Body(name: \"b\", shape: Ball(radius: 1.0), {fields})])"
        ));
        assert_eq!(f, field, "{fields}");
        assert!(m.contains(limit), "{fields}: {m}");
    }
    // Just inside the limits, the same bodies load.
    for fields in [
        "linear_velocity: (0.0, -9.9e4, 0.0)",
        "angular_velocity: (0.0, 9.9e3, 0.0)",
        "mass: 1e24",
        "density: 1e12",
    ] {
        let text =
            format!("Scene(bodies: [Body(name: \"b\", shape: Ball(radius: 1.0), {fields})])");
        assert!(Scene::parse(&text, "ok.ron").is_ok(), "{fields}");
    }
}

#[test]
fn a_rotation_of_any_finite_length_is_normalised_without_overflow() {
    // (0, 0, 0, 1e30) squared overflows f32: normalised naively it was NaN at the first step.
    let scene = Scene::parse(
        "Scene(gravity: (0.0, 0.0, 0.0), bodies: [Body(name: \"b\", shape: Cuboid(half_extents: (1.0, 1.0, 1.0)), rotation: (0.0, 0.0, 1e30, 1e30))])",
        "big.ron",
    )
    .expect("a finite non-zero quaternion is a rotation");
    let mut world = scene.build().expect("builds");
    world.step(scene.dt).expect("steps");
    let (_, _, body) = world.bodies().next().expect("one body");
    let expected = jostle::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    assert!(body.orientation.is_finite());
    assert!(
        body.orientation.dot(expected).abs() > 1.0 - 1e-6,
        "{:?}",
        body.orientation
    );
}

#[test]
fn duplicate_body_names_are_refused() {
    let (body, field) = body_field(
        "Scene(bodies: [Body(name: \"a\", shape: Ball(radius: 1.0)), Body(name: \"a\", shape: Ball(radius: 1.0), position: (3.0, 0.0, 0.0))])",
    );
    assert_eq!((body.as_str(), field.as_str()), ("a", "name"));
    // Bodies without a name are known by their place: several may go unnamed (two were
    // refused as sharing the name "").
    let scene = Scene::parse(
        "Scene(bodies: [Body(shape: Ball(radius: 1.0)), Body(shape: Ball(radius: 1.0), position: (3.0, 0.0, 0.0))])",
        "unnamed.ron",
    );
    assert!(scene.is_ok(), "{:?}", scene.err());
    // Two unnamed generators of one kind make the same names: the error says how to tell
    // them apart.
    let scene = Scene::parse(
        "Scene(generators: [Stack(count: 2), Stack(count: 2, origin: (3.0, 0.0, 0.0))])",
        "stacks.ron",
    )
    .expect("parses");
    let e = scene.build().err().expect("refused").to_string();
    assert!(
        e.contains("stack-0") && e.contains("give each generator of the same kind its own `name:`"),
        "{e}"
    );
}

#[test]
fn validation_errors_name_the_line_and_column_of_the_field() {
    let text = "Scene(name: \"s\",\n  bodies: [\n    Body(name: \"a\", shape: Ball(radius: 0.5)),\n    Body(name: \"b\", shape: Ball(radius: 0.5),\n         mass: -1.0),\n  ])\n";
    let e = error(text).to_string();
    assert!(
        e.starts_with("bad.ron:5:10: bodies[1]: body \"b\": field `mass`"),
        "{e}"
    );
    // A repeated name at the body that repeats it.
    let text = "Scene(name: \"s\", bodies: [\n Body(name: \"a\", shape: Ball(radius: 0.5)),\n Body(name: \"a\", shape: Ball(radius: 0.5))])";
    let e = error(text).to_string();
    assert!(
        e.starts_with("bad.ron:3:7: body \"a\": field `name`"),
        "{e}"
    );
    // A setting of the resolver.
    let text = "Scene(name: \"s\",\n resolver: SoftStep(\n   substeps: 0),\n bodies: [])";
    let e = error(text).to_string();
    assert!(
        e.starts_with("bad.ron:3:4: field `resolver.substeps`"),
        "{e}"
    );
}

#[test]
fn two_confusing_parse_errors_carry_a_hint() {
    let e = error("Scene(name: \"s\", steps: 10.5, bodies: [])").to_string();
    assert!(e.contains("a whole number is expected"), "{e}");
    let e = error("Scene(name: \"s\", sleep: Some(SleepSettings(enabled: false)), bodies: [])")
        .to_string();
    assert!(e.contains("`sleep: (enabled: false)`"), "{e}");
    // The same mistake with another type's name, or `Some` around plain parentheses (ron said
    // "Unexpected field named `Camera` in `Scene`" and "Expected identifier").
    for text in [
        "Scene(camera: Some(Camera(position: (1.0, 2.0, 3.0))))",
        "Scene(sleep: Some((threshold: 0.5)))",
    ] {
        let e = error(text).to_string();
        assert!(
            e.contains("without `Some` or the type's name"),
            "{text}: {e}"
        );
    }
    // A resolver's settings in double parentheses (ron said "Expected identifier").
    for text in [
        "Scene(resolver: SoftStep((substeps: 4)))",
        "Scene(resolver: Millington((velocity_iterations: 4)))",
    ] {
        let e = error(text).to_string();
        assert!(e.contains("in one pair of parentheses"), "{text}: {e}");
    }
}

#[test]
fn a_shape_too_small_for_f32_names_its_size_field() {
    let scene = Scene::parse(
        "Scene(name: \"s\", bodies: [Body(name: \"t\", shape: Ball(radius: 1e-30))])",
        "bad.ron",
    )
    .expect("parses: the mass is computed when the world is built");
    let e = scene.build().err().expect("refused").to_string();
    assert!(e.contains("body \"t\": field `shape.radius`"), "{e}");
    assert!(e.contains("no usable mass"), "{e}");
}

#[test]
fn a_body_without_a_name_is_named_by_its_place_in_the_list() {
    let text = "Scene(bodies: [\n    Body(shape: Ball(radius: 0.5)),\n    Body(shape: Ball(radius: 0.5), friction: -1.0),\n])";
    let e = error(text);
    match &e {
        SceneError::Body {
            index: Some(1),
            at: Some((3, 36)),
            ..
        } => {}
        other => panic!("expected bodies[1] at 3:36, got {other:?}"),
    }
    let message = e.to_string();
    assert!(
        message.starts_with("bad.ron:3:36: bodies[1]: ") && message.contains("`friction`"),
        "{message}"
    );
}

#[test]
fn a_kinematic_body_moved_by_poses_or_a_path_refuses_a_velocity() {
    // Shown at step 0 and dropped at the first step before: the poses decide the motion.
    for kinematic in [
        "Position",
        "Line(offset: (1.0, 0.0, 0.0), period: 2.0)",
        "Turn(center: (0.0, 0.0, 0.0), axis: (0.0, 1.0, 0.0), period: 2.0)",
    ] {
        for (field, value) in [
            ("linear_velocity", "(1.0, 0.0, 0.0)"),
            ("angular_velocity", "(0.0, 2.0, 0.0)"),
        ] {
            let text = format!(
                "Scene(bodies: [Body(name: \"pad\", shape: Cuboid(half_extents: (0.5, 0.5, 0.5)), \
                 kinematic: {kinematic}, {field}: {value})])"
            );
            let (body, f) = body_field(&text);
            assert_eq!((body.as_str(), f.as_str()), ("pad", field), "{kinematic}");
        }
    }
    // Moved by its velocity, it takes one.
    let ok = Scene::parse(
        "Scene(bodies: [Body(name: \"pad\", shape: Cuboid(half_extents: (0.5, 0.5, 0.5)), \
         kinematic: Velocity, linear_velocity: (1.0, 0.0, 0.0))])",
        "ok.ron",
    );
    assert!(ok.is_ok(), "{:?}", ok.err());
}
