//! Numerical-stability stress suite (issue: "stress-test numerical stability"). Every case runs
//! with both resolvers and must stay finite, never panic and never quarantine a body; cases
//! with a physical criterion ("held") assert it where the engine meets it, and the outcome of
//! every case is printed as a table (`cargo test --test stress -- --nocapture`).
//!
//! Heavier variants (100,000-step run, 100-box tower, 1:10,000 mass ratio at length) are
//! `#[ignore]`d; run them with
//! `cargo test --release --test stress -- --ignored --nocapture`.

use jostle::{
    BodyDesc, MillingtonSettings, Quat, ResolverChoice, ShapeDesc, SoftStepSettings, Vec3, World,
    WorldSettings,
};

const DT: f32 = 1.0 / 60.0;

fn resolvers() -> [(&'static str, ResolverChoice); 2] {
    [
        (
            "millington",
            ResolverChoice::Millington(MillingtonSettings::default()),
        ),
        (
            "soft-step",
            ResolverChoice::SoftStep(SoftStepSettings::default()),
        ),
    ]
}

fn world(resolver: &ResolverChoice) -> World {
    let mut s = WorldSettings {
        resolver: resolver.clone(),
        ..Default::default()
    };
    s.sleep.enabled = false;
    World::new(s)
}

fn ground(w: &mut World, at: Vec3) {
    w.add_body(
        BodyDesc::fixed("ground", ShapeDesc::HalfSpace { normal: Vec3::Y })
            .at(at)
            .with_material(0.6, 0.0),
    )
    .unwrap();
}

/// Steps `seconds`, asserting finiteness and no quarantine every step; returns the largest
/// displacement of any dynamic body between `settle` seconds and the end.
fn run_checked(w: &mut World, seconds: f32, settle: f32, case: &str) -> f32 {
    let n = (seconds / DT).round() as u32;
    let settle_step = (settle / DT).round() as u32;
    let mut at_settle: Vec<Vec3> = Vec::new();
    for step in 1..=n {
        let report = w
            .step(DT)
            .unwrap_or_else(|e| panic!("{case}: step refused: {e}"));
        assert!(
            report.quarantined.is_empty(),
            "{case}: quarantined {:?} at step {step}",
            report.quarantined
        );
        if step == settle_step {
            at_settle = w
                .bodies()
                .filter(|(_, _, b)| !b.is_fixed())
                .map(|(_, _, b)| b.position)
                .collect();
        }
    }
    for (_, name, b) in w.bodies() {
        assert!(b.is_finite(), "{case}: {name} went non-finite");
    }
    w.bodies()
        .filter(|(_, _, b)| !b.is_fixed())
        .zip(&at_settle)
        .map(|((_, _, b), p)| (b.position - *p).length())
        .fold(0.0, f32::max)
}

fn cube(name: &str, half: f32, at: Vec3, mass: f32) -> BodyDesc {
    BodyDesc::dynamic(
        name,
        ShapeDesc::Cuboid {
            half_extents: Vec3::splat(half),
        },
    )
    .at(at)
    .with_mass(mass)
    .with_material(0.6, 0.0)
}

/// A light box under a heavy one: (drift 1 s → `seconds`, how far the top sank).
fn mass_ratio(resolver: &ResolverChoice, ratio: f32, seconds: f32) -> (f32, f32) {
    let mut w = world(resolver);
    ground(&mut w, Vec3::ZERO);
    w.add_body(cube("light", 0.5, Vec3::new(0.0, 0.5, 0.0), 1.0))
        .unwrap();
    let top = w
        .add_body(cube("heavy", 0.5, Vec3::new(0.0, 1.5, 0.0), ratio))
        .unwrap();
    let drift = run_checked(&mut w, seconds, 1.0, &format!("mass ratio 1:{ratio}"));
    (drift, 1.5 - w.body(top).unwrap().position.y)
}

#[test]
fn mass_ratio_stacks_stay_finite_and_moderate_ratios_hold() {
    println!(
        "{:<12} {:>8} {:>10} {:>10}",
        "resolver", "ratio", "drift m", "sank m"
    );
    for (name, r) in resolvers() {
        for ratio in [10.0, 100.0, 1000.0, 10_000.0] {
            let (drift, sank) = mass_ratio(&r, ratio, 4.0);
            println!("{name:<12} {ratio:>8} {drift:>10.4} {sank:>10.4}");
            // Measured (4 s, 60 Hz): both hold 1:10. At 1:100 and beyond the Millington
            // resolver lets the heavy box sink through the light one (1.0 m); soft-step holds
            // 1:100 to 3.4 cm, sinks 0.34 m at 1:1000 and through at 1:10,000. Open work,
            // reported rather than asserted; finiteness is asserted for every ratio.
            if ratio <= 10.0 {
                assert!(
                    drift < 0.01 && sank < 0.02,
                    "{name} 1:{ratio}: drift {drift}, sank {sank}"
                );
            }
        }
    }
}

/// Issue 16 item 6: a box under one 10⁶ times heavier on a fixed floor 10 cm thick, boxes of
/// 0.1, 1 and 10 m, μ 0.3 and 0.9, the heavy box started exactly and at offsets of 0.6% and
/// −1.4% of the box. The stack need not hold, but no body's centre may ever reach the floor's
/// top: none is pushed into or through fixed geometry (with the soft step 17 of the 18 light
/// boxes also stay within 1 mm of their start; `--nocapture` prints how far each moved). It
/// used to be thrown sideways (11 m within one step, 2,678 m/s, for a unit box 3 mm off
/// centre), two of them through the floor: its direct solve built the island's J·M⁻¹·Jᵀ in
/// f32, where the heavy box's part is rounding, and the matrix had a negative eigenvalue
/// (benches/RESULTS.md, "A million to one").
#[test]
fn a_million_to_one_load_never_pushes_a_body_through_the_floor_soft_step() {
    let (name, resolver) = &resolvers()[1];
    let failed = million_to_one_family(name, resolver);
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// The same family with the Millington resolver: its shock sweep resolves what the
/// worst-first picks leave of the heavy box's load with the light box held still, so the
/// load reaches the floor (without it the light box was squeezed out by up to 10 m and a 0.1 m
/// one pushed through the floor).
#[test]
fn a_million_to_one_family_never_pushes_a_body_through_the_floor_millington() {
    let (name, resolver) = &resolvers()[0];
    let failed = million_to_one_family(name, resolver);
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// The Millington resolver on unit boxes at μ 0.6, the heavy box exactly above and 3 mm and
/// −7 mm off: nothing reaches the floor's top.
#[test]
fn a_million_to_one_load_never_pushes_a_body_through_the_floor_millington() {
    let (name, resolver) = &resolvers()[0];
    for offset in [0.0f32, 0.003, -0.007] {
        million_to_one_case(name, resolver, 0.5, 0.6, offset).unwrap();
    }
}

/// Touching bodies whose masses differ by more than `MAX_CONTACT_MASS_RATIO` (10⁶), which
/// the soft step's contacts cannot hold in f32 (a 1 kg box under 10⁷ kg is pressed 0.25 m into
/// its neighbour or thrown out), are reported every step they touch, lighter first, whichever
/// was added first; a pair within it is not, nor a heavy body locked along every axis of
/// translation (it cannot be moved), nor any pair under the Millington resolver, whose shock
/// sweep holds the light box (0.3–0.4 mm up to 1:10¹²).
#[test]
fn touching_bodies_beyond_the_contact_mass_ratio_are_reported() {
    let cases = [(5.0e5f32, false), (2.0e6, true), (1.0e12, true)];
    for (name, r) in resolvers() {
        let soft = name == "soft-step";
        for (ratio, beyond) in cases {
            for heavy_first in [false, true] {
                for locked in [false, true] {
                    let mut w = world(&r);
                    ground(&mut w, Vec3::ZERO);
                    let light = cube("light", 0.5, Vec3::new(0.0, 0.5, 0.0), 1.0);
                    let mut heavy = cube("heavy", 0.5, Vec3::new(0.0, 1.5, 0.0), ratio);
                    if locked {
                        heavy = heavy.with_translation_locks([true; 3]);
                    }
                    let (light, heavy) = if heavy_first {
                        let h = w.add_body(heavy).unwrap();
                        (w.add_body(light).unwrap(), h)
                    } else {
                        let l = w.add_body(light).unwrap();
                        (l, w.add_body(heavy).unwrap())
                    };
                    let report = w.step(DT).unwrap();
                    let expected = if soft && beyond && !locked {
                        vec![(light, heavy)]
                    } else {
                        vec![]
                    };
                    assert_eq!(
                        report.beyond_mass_ratio, expected,
                        "{name} 1:{ratio}, heavy first {heavy_first}, locked {locked}"
                    );
                }
            }
        }
    }
}

/// Every case of the 1:10⁶ family that fails, by name.
fn million_to_one_family(name: &str, resolver: &ResolverChoice) -> Vec<String> {
    let mut failed = Vec::new();
    for half in [0.05f32, 0.5, 5.0] {
        for friction in [0.3f32, 0.9] {
            for offset in [0.0f32, 0.006, -0.014] {
                let offset = offset * 2.0 * half;
                if let Err(e) = million_to_one_case(name, resolver, half, friction, offset) {
                    failed.push(e);
                }
            }
        }
    }
    failed
}

/// One case of the 1:10⁶ family, 600 steps: `Err` names the body that reached the floor's
/// top. Prints how far the light box moved.
fn million_to_one_case(
    name: &str,
    resolver: &ResolverChoice,
    half: f32,
    friction: f32,
    offset: f32,
) -> Result<(), String> {
    let mut w = world(resolver);
    w.add_body(
        BodyDesc::fixed(
            "floor",
            ShapeDesc::Cuboid {
                half_extents: Vec3::new(10.0, 0.05, 10.0),
            },
        )
        .at(Vec3::new(0.0, -0.05, 0.0))
        .with_material(friction, 0.0),
    )
    .unwrap();
    let mass = 8.0 * half * half * half * 1000.0;
    let light = cube("light", half, Vec3::new(0.0, half, 0.0), mass).with_material(friction, 0.0);
    let heavy = cube(
        "heavy",
        half,
        Vec3::new(offset, 3.0 * half, 0.0),
        mass * 1e6,
    )
    .with_material(friction, 0.0);
    w.add_body(light).unwrap();
    w.add_body(heavy).unwrap();
    for step in 0..600 {
        let report = w.step(DT).unwrap();
        assert!(report.quarantined.is_empty(), "{name}: quarantined");
        for (_, body, b) in w.bodies().filter(|(_, _, b)| !b.is_fixed()) {
            if b.position.y.is_nan() || b.position.y <= 0.0 {
                return Err(format!(
                    "{name}, half {half}, μ {friction}, offset {offset}: {body} at y = {} at step {step}",
                    b.position.y
                ));
            }
        }
    }
    let light = w.bodies().find(|(_, n, _)| *n == "light").unwrap().2;
    let moved = light.position.distance(Vec3::new(0.0, half, 0.0));
    println!(
        "{name}, half {half}, μ {friction}, offset {offset}: the light box moved {moved:.5} m"
    );
    Ok(())
}

#[test]
fn boxes_from_1_cm_to_100_m_rest_at_their_height() {
    println!(
        "{:<12} {:>8} {:>12} {:>10}",
        "resolver", "size m", "rest error", "drift"
    );
    for (name, r) in resolvers() {
        for half in [0.005f32, 0.05, 0.5, 5.0, 50.0] {
            let mut w = world(&r);
            ground(&mut w, Vec3::ZERO);
            let h = w
                .add_body(cube(
                    "box",
                    half,
                    Vec3::new(0.0, 1.02 * half, 0.0),
                    1000.0 * 8.0 * half.powi(3),
                ))
                .unwrap();
            let drift = run_checked(&mut w, 3.0, 1.5, &format!("{name} size {half}"));
            let err = (w.body(h).unwrap().position.y - half).abs();
            println!("{name:<12} {:>8} {err:>12.5} {drift:>10.5}", 2.0 * half);
            // Rests on the ground: not fallen through, not floating.
            assert!(
                w.body(h).unwrap().position.y > 0.0,
                "{name}: {half} fell through"
            );
            assert!(
                err < 0.01 * half.max(0.5),
                "{name} size {}: rest error {err}",
                2.0 * half
            );
        }
    }
}

/// A box resting under gravity up to [`jostle::MAX_GRAVITY`] (10⁴ g) is held, whatever its
/// size. The soft step caps a contact's bias at its push-out speed, its load included: at a
/// fixed `max_push_out` (3 m/s), where a spring needed more than that to carry its load (a
/// unit box under 10⁵ m/s², 8.6 m/s at the default substeps) the box sank without end, 38 m in
/// 10 s. The push-out speed now grows with gravity beyond 9.81 m/s²
/// (`soft_step::push_out_speed`), and the spring settles as at any gravity.
#[test]
fn a_box_under_the_largest_gravity_is_held() {
    for (name, r) in resolvers() {
        for g in [1.0e3f32, 1.0e4, jostle::MAX_GRAVITY] {
            for half in [0.05f32, 0.5, 5.0] {
                let mut w = world(&r);
                w.set_gravity(Vec3::new(0.0, -g, 0.0)).unwrap();
                ground(&mut w, Vec3::ZERO);
                let h = w
                    .add_body(cube(
                        "box",
                        half,
                        Vec3::new(0.0, half, 0.0),
                        1000.0 * 8.0 * half.powi(3),
                    ))
                    .unwrap();
                let case = format!("{name} g {g} size {}", 2.0 * half);
                run_checked(&mut w, 5.0, 5.0, &case);
                let sink_5 = half - w.body(h).unwrap().position.y;
                run_checked(&mut w, 5.0, 5.0, &case);
                let sink_10 = half - w.body(h).unwrap().position.y;
                println!("{case}: sink at 5 s {sink_5:.5} m, at 10 s {sink_10:.5} m");
                // Held: no deeper than 5 mm, and the soft step not sinking any further. (The
                // Millington resolver lets a resting contact creep, 61 µm/s under 10⁵ m/s²,
                // until its position pass acts at `position_epsilon`, 1 cm.)
                assert!(sink_10.abs() < 5e-3, "{case}: sank {sink_10} m");
                let creep = if name == "soft-step" { 1e-4 } else { 1e-3 };
                assert!(
                    sink_10 <= sink_5 + creep,
                    "{case}: sinking, {sink_5} → {sink_10} m"
                );
            }
        }
    }
}

/// The largest speed of body `name` over a run of the scene `text` with `resolver`, and the
/// fastest any kinematic body of it moved.
fn fastest(text: &str, resolver: &ResolverChoice, name: &str) -> (f32, f32) {
    let scene = jostle::scene::Scene::parse(text, "crush.ron").expect("scene parses");
    let mut w = scene.build().expect("scene builds");
    w.set_resolver_choice(resolver.clone())
        .expect("resolver accepted");
    let h = w.find_body(name).expect("the body is in the scene");
    let movers: Vec<_> = w
        .bodies()
        .filter(|(_, _, b)| b.is_kinematic())
        .map(|(k, _, _)| k)
        .collect();
    let (mut fastest, mut mover) = (0.0f32, 0.0f32);
    for _ in 0..scene.steps {
        w.step(scene.dt).expect("steps");
        fastest = fastest.max(w.body(h).unwrap().linear_velocity.length());
        for &k in &movers {
            mover = mover.max(w.body(k).unwrap().linear_velocity.length());
        }
    }
    (fastest, mover)
}

/// Boxes of 0.1, 0.2 and 0.5 m crushed between two kinematic walls that close on them, or
/// pushed by one into a fixed wall (an infeasible squeeze: the walls pass through the box or
/// it through them), leave no faster than the walls move plus the push-out speed, walls
/// closing in 4 and 20 s. The soft step's push-out cap once applied only beyond a contact's
/// load, so that the crushed box's springs ratcheted their load up step after step, and the
/// 0.5 m box left at 31 m/s between walls moving at 1.6 m/s (44 m/s against the fixed wall).
/// Until the carried friction was kept in the cone of the first pass's normal impulse
/// (`keep_in_cone` in the soft step's kernels), the 0.1 and 0.2 m boxes were thrown at 5–10
/// m/s by walls moving at 0.06–0.9 m/s.
///
/// Not yet for every size: scaled to boxes of 1, 2, 5 and 10 m, 7 of their 16 squeezes still
/// throw the box out faster (the 10 m box at 73 m/s between walls closing at 31 m/s), and the
/// Millington resolver throws the box pushed into the fixed wall at 20.6 m/s
/// (benches/RESULTS.md, "A crushed box thrown out"; `CRUSH_SIZES=0.1,1,10 cargo test --release
/// --test stress crushed -- --nocapture` prints them and fails).
#[test]
fn crushed_boxes_up_to_half_a_metre_leave_no_faster_than_the_walls_and_push_out() {
    let soft = SoftStepSettings::default();
    let resolver = ResolverChoice::SoftStep(soft.clone());
    let sizes: Vec<f32> = std::env::var("CRUSH_SIZES")
        .map(|v| v.split(',').filter_map(|x| x.parse().ok()).collect())
        .unwrap_or(vec![0.1, 0.2, 0.5]);
    let mut thrown = Vec::new();
    for size in sizes {
        let k = size / 0.5;
        for period in [4.0f32, 20.0] {
            let steps = (period * 0.75 / DT) as u32;
            // A slab of half extents `h` at x, resting on the ground, as scene text.
            let slab = |name: &str, h: Vec3, x: f32, motion: &str| {
                format!(
                    "Body(name: \"{name}\", shape: Cuboid(half_extents: ({}, {}, {})), \
                     position: ({x}, {}, 0.0), {motion}),",
                    h.x, h.y, h.z, h.y
                )
            };
            let line = |offset: f32| {
                format!("kinematic: Line(offset: ({offset}, 0.0, 0.0), period: {period})")
            };
            let scene = |walls: [String; 2]| {
                format!(
                    "Scene(name: \"crush\", steps: {steps}, sleep: (enabled: false), bodies: [
                       Body(name: \"ground\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true),
                       {} {} {}])",
                    walls[0],
                    walls[1],
                    slab("box", Vec3::splat(0.25 * k), 0.0, "")
                )
            };
            let mover = Vec3::new(0.1, 0.5, 1.0) * k;
            let closing = scene([
                slab("left", mover, -2.0 * k, &line(2.0 * k)),
                slab("right", mover, 2.0 * k, &line(-2.0 * k)),
            ]);
            let against_wall = scene([
                slab("wall", Vec3::new(0.2, 1.0, 2.0) * k, 1.1 * k, "fixed: true"),
                slab("pusher", mover, -2.0 * k, &line(3.0 * k)),
            ]);
            for (kind, text) in [("closing walls", closing), ("against a wall", against_wall)] {
                let (fastest, mover) = fastest(&text, &resolver, "box");
                let case = format!("{kind}, {size} m box, period {period} s");
                println!("{case}: box at most {fastest:.2} m/s, walls {mover:.2} m/s");
                if fastest > mover + soft.max_push_out {
                    thrown.push(format!(
                        "{case}: the box left at {fastest} m/s, the walls moved at {mover} m/s"
                    ));
                }
            }
        }
    }
    // Every case first, then the verdict: a run over other sizes prints its whole table.
    assert!(thrown.is_empty(), "{thrown:#?}");
}

#[test]
fn a_box_ten_kilometres_from_the_origin_rests_and_does_not_drift() {
    for (name, r) in resolvers() {
        let far = Vec3::new(10_000.0, 0.0, 10_000.0);
        let mut w = world(&r);
        ground(&mut w, far);
        let h = w
            .add_body(cube("far", 0.5, far + Vec3::new(0.0, 0.5, 0.0), 1000.0))
            .unwrap();
        let drift = run_checked(&mut w, 4.0, 1.0, "10 km");
        let y = w.body(h).unwrap().position.y;
        println!("{name}: 10 km from the origin: drift {drift} m, rests at y = {y}");
        // f32 resolves 10 km to ~1 mm; the box must not wander more than a few of those.
        assert!(
            drift < 0.01 && (y - 0.5).abs() < 0.02,
            "{name}: drift {drift}, y {y}"
        );
    }
}

/// Balls shot at `speed` into a static wall `thickness` thick; returns how many of 8 start
/// offsets ended beyond the wall (tunnelled).
fn tunnels(resolver: &ResolverChoice, speed: f32, thickness: f32) -> usize {
    (0..8)
        .filter(|&k| {
            let mut s = WorldSettings {
                gravity: Vec3::ZERO,
                resolver: resolver.clone(),
                ..Default::default()
            };
            s.sleep.enabled = false;
            let mut w = World::new(s);
            w.add_body(BodyDesc::fixed(
                "wall",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::new(thickness / 2.0, 2.0, 2.0),
                },
            ))
            .unwrap();
            let start = -1.0 - speed * DT * k as f32 / 8.0;
            let b = w
                .add_body(
                    BodyDesc::dynamic("bullet", ShapeDesc::Ball { radius: 0.05 })
                        .at(Vec3::new(start, 0.0, 0.0))
                        .moving(Vec3::new(speed, 0.0, 0.0), Vec3::ZERO),
                )
                .unwrap();
            let steps = ((2.0 - start) / (speed * DT)).ceil() as u32 + 2;
            for _ in 0..steps {
                w.step(DT).unwrap();
            }
            let x = w.body(b).unwrap().position.x;
            assert!(x.is_finite());
            x > 0.0
        })
        .count()
}

#[test]
fn fast_bodies_into_thin_walls_stay_finite_and_the_tunnelling_is_reported() {
    println!(
        "{:<12} {:>8} {:>10} {:>9}",
        "resolver", "speed", "wall m", "tunnel/8"
    );
    for (name, r) in resolvers() {
        for speed in [10.0f32, 50.0, 200.0] {
            for thickness in [0.01f32, 0.05, 0.2] {
                let n = tunnels(&r, speed, thickness);
                println!("{name:<12} {speed:>8} {thickness:>10} {n:>9}");
                if speed * DT < 0.1 + thickness {
                    // Slower than one ball diameter plus the wall per step: caught without CCD.
                    assert_eq!(n, 0, "{name}: {speed} m/s through {thickness} m");
                }
            }
        }
    }
}

fn tower(resolver: &ResolverChoice, boxes: u32, seconds: f32) -> f32 {
    let mut w = world(resolver);
    ground(&mut w, Vec3::ZERO);
    for i in 0..boxes {
        w.add_body(cube(
            &format!("t{i}"),
            0.5,
            Vec3::new(0.0, 0.5 + i as f32, 0.0),
            1000.0,
        ))
        .unwrap();
    }
    run_checked(&mut w, seconds, 1.0, &format!("tower of {boxes}"))
}

#[test]
fn a_20_box_tower_stays_finite() {
    for (name, r) in resolvers() {
        let drift = tower(&r, 20, 3.0);
        println!("{name}: tower of 20, drift from 1 s to 3 s {drift} m");
    }
}

#[test]
#[ignore = "heavy: 100-box towers for 10 s; run with --release --ignored"]
fn a_100_box_tower_stays_finite() {
    for (name, r) in resolvers() {
        let drift = tower(&r, 100, 10.0);
        println!("{name}: tower of 100, drift from 1 s to 10 s {drift} m");
    }
}

/// Total energy (kinetic + gravitational) of the dynamic bodies.
fn energy(w: &World) -> f64 {
    let g = w.settings().gravity;
    w.bodies()
        .filter(|(_, _, b)| !b.is_fixed())
        .map(|(_, _, b)| b.kinetic_energy() as f64 - (b.mass() * g.dot(b.position)) as f64)
        .sum()
}

fn long_run(resolver: &ResolverChoice, steps: u32) -> (f64, f64) {
    let mut w = world(resolver);
    ground(&mut w, Vec3::ZERO);
    for i in 0..6 {
        let shape = if i % 2 == 0 {
            ShapeDesc::Ball { radius: 0.3 }
        } else {
            ShapeDesc::Cuboid {
                half_extents: Vec3::splat(0.3),
            }
        };
        w.add_body(
            BodyDesc::dynamic(format!("b{i}"), shape)
                .at(Vec3::new(i as f32 * 0.9 - 2.0, 1.0 + i as f32 * 0.7, 0.0))
                .rotated(Quat::from_rotation_z(0.3 * i as f32))
                .moving(Vec3::new(1.0, 0.0, 0.5), Vec3::new(0.0, 2.0, 1.0))
                .with_material(0.4, 0.5),
        )
        .unwrap();
    }
    let e0 = energy(&w);
    let mut worst = e0;
    for _ in 0..steps {
        let r = w.step(DT).unwrap();
        assert!(r.quarantined.is_empty());
        worst = worst.max(energy(&w));
    }
    (e0, worst)
}

#[test]
fn energy_stays_bounded_over_a_long_run() {
    for (name, r) in resolvers() {
        let (e0, worst) = long_run(&r, 5_000);
        println!("{name}: 5,000 steps: energy {e0:.2} J at start, at most {worst:.2} J");
        // No external work: the total energy never rises above its start (1% allowance for the
        // discrete contact timing of the first impacts).
        assert!(
            worst <= e0 * 1.01 + 1e-3,
            "{name}: energy grew from {e0} to {worst}"
        );
    }
}

/// Long steps for `assets/pyramid_heavy_top.ron` (a 10-row pyramid whose top box is 100 times
/// heavier): 0.4 to 1.5 s.
const LONG_STEPS: [f32; 11] = [0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.5];

/// `assets/pyramid_heavy_top.ron` stepped with `resolver` at `dt` for 12 s: its mechanical
/// energy at the start, after the first step and at its highest.
fn heavy_top_at(resolver: &ResolverChoice, dt: f32) -> (f64, f64, f64) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/pyramid_heavy_top.ron");
    let text = std::fs::read_to_string(path).expect("asset");
    let scene = jostle::scene::Scene::parse(&text, path).expect("scene");
    let mut settings = scene.settings();
    settings.resolver = resolver.clone();
    let mut w = scene.build_with(settings).expect("world");
    let e0 = energy(&w);
    let (mut first, mut worst) = (e0, e0);
    for k in 0..(12.0 / dt).round() as usize {
        let report = w.step(dt).unwrap();
        assert!(report.quarantined.is_empty(), "{}", resolver.name());
        worst = worst.max(energy(&w));
        if k == 0 {
            first = energy(&w);
        }
    }
    (e0, first, worst)
}

/// `assets/pyramid_heavy_top.ron` stepped at `dt` 0.4 to 1.5 s with each resolver at its
/// defaults. The soft step: its mechanical energy never rises above the start by more than
/// 10⁻⁴ of it over 12 s (measured: not by a joule; it collapses in its first step). The
/// Millington resolver: its first step gains at most 10⁻⁴. That step gained 328,829 J (3%) at
/// `dt` 1.0 while its velocity pass let a resting contact that another pair's pick had driven
/// apart keep its new separating speed, so the push that drove it apart was never taken back
/// (benches/RESULTS.md, "Resting contacts driven apart take back their push"); measured after:
/// at most 123 J (1.1·10⁻⁵). Its collapse a few steps later still gains energy (the ignored
/// test below).
#[test]
fn a_pyramid_with_a_heavy_top_stepped_at_long_steps_gains_no_energy() {
    let mut wrong = Vec::new();
    for (name, r) in resolvers() {
        for dt in LONG_STEPS {
            let (e0, first, worst) = heavy_top_at(&r, dt);
            println!(
                "{name}: dt {dt}: energy {e0:.0} J at start, {first:.0} J after the first step, at most {worst:.0} J"
            );
            let held = match r {
                ResolverChoice::Millington(_) => first,
                _ => worst,
            };
            if held - e0 > 1e-4 * e0 {
                wrong.push(format!("{name}, dt {dt}: rose by {:.0} J", held - e0));
            }
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// The Millington resolver's whole run in the test above: not met. Once the pyramid collapses
/// its velocity pass throws bodies and its position pass lifts the 100 t top out of the
/// overlaps it sank into (with an earlier form of the friction fix named below, at `dt` 1.1 one step
/// threw the top, at rest on the apex, 3.3 m up at 3 m/s and 6 rad/s, 4.9 MJ; at `dt` 0.4 one
/// lifted it 0.35 m out of the boxes under it, 344 kJ). Measured rises over 12 s, in 10⁻³ of
/// the energy, `dt` 0.4 … 1.5 as in `LONG_STEPS`: 0.098, 20, 31, 1.0, 0.066, 3.1, 0.31, 12,
/// 4.7, 1.4, 7.5 (before the dynamic friction fix of
/// `friction_is_dynamic_once_sliding_whatever_mu` in jostle-resolve: 6.8, 32.4, 14.1, 40.1,
/// 5.8, 16.9, 0.06, 48.1, 0.15, 5.8, 0.24; the pass at `dt` 1.0 that the test above once
/// asserted over the whole run was one of these draws). With the shock sweep off nothing
/// rises at any of these steps, but the sweep is what holds a heavy top up
/// (`tests/stability_family.rs`,
/// `without_the_shock_sweep_the_millington_resolver_lets_a_heavy_box_down`).
#[test]
#[ignore = "open (issue 16 item 6): the Millington resolver's collapse at long steps gains energy"]
fn the_millington_resolvers_collapse_at_long_steps_gains_no_energy() {
    let millington = ResolverChoice::Millington(MillingtonSettings::default());
    let mut wrong = Vec::new();
    for dt in LONG_STEPS {
        let (e0, _, worst) = heavy_top_at(&millington, dt);
        println!("dt {dt}: energy {e0:.0} J at start, at most {worst:.0} J");
        if worst - e0 > 1e-4 * e0 {
            wrong.push(format!("dt {dt}: rose by {:.0} J", worst - e0));
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

#[test]
#[ignore = "heavy: 100,000 steps; run with --release --ignored"]
fn energy_stays_bounded_over_100_000_steps() {
    for (name, r) in resolvers() {
        let (e0, worst) = long_run(&r, 100_000);
        println!("{name}: 100,000 steps: energy {e0:.2} J at start, at most {worst:.2} J");
        assert!(
            worst <= e0 * 1.01 + 1e-3,
            "{name}: energy grew from {e0} to {worst}"
        );
    }
}

#[test]
fn degenerate_shapes_stay_finite_or_are_refused_clearly() {
    // A perfectly flat hull has no volume: refused with a field-naming error, not a panic.
    let flat = ShapeDesc::ConvexHull {
        points: vec![Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::new(1.0, 0.0, 1.0)],
    };
    let e = World::new(WorldSettings::default())
        .add_body(BodyDesc::dynamic("flat", flat))
        .unwrap_err();
    assert!(e.to_string().contains("flat"), "{e}");
    for (name, r) in resolvers() {
        let mut w = world(&r);
        // A floor of sliver triangles (1 mm wide, 20 m long).
        let mut vertices = Vec::new();
        let mut indices = Vec::new();
        for i in 0..40u32 {
            let z = i as f32 * 0.001 - 0.02;
            vertices.extend([Vec3::new(-10.0, 0.0, z), Vec3::new(10.0, 0.0, z)]);
            if i > 0 {
                let (a, b, c, d) = (2 * i - 2, 2 * i - 1, 2 * i, 2 * i + 1);
                indices.extend([[a, c, b], [b, c, d]]);
            }
        }
        w.add_body(BodyDesc::fixed(
            "slivers",
            ShapeDesc::TriMesh { vertices, indices },
        ))
        .unwrap();
        ground(&mut w, Vec3::new(0.0, -1.0, 0.0));
        // A hull 0.1 mm or 1 mm thick has no usable mass: refused, naming the body and field.
        let sliver_hull = |h: f32| ShapeDesc::ConvexHull {
            points: vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::Z,
                Vec3::new(1.0, 0.0, 1.0),
                Vec3::new(0.5, h, 0.5),
            ],
        };
        // parry treats features under ~1 mm on a 1 m hull as coplanar.
        for h in [1e-4, 1e-3] {
            let e = w
                .add_body(BodyDesc::dynamic("sliver", sliver_hull(h)))
                .unwrap_err();
            assert!(
                e.to_string().contains("\"sliver\"") && e.to_string().contains("shape.points"),
                "{e}"
            );
        }
        // Nearly flat hull (1 cm thick), needle capsule (1 mm radius, 2 m long).
        let thin = sliver_hull(1e-2);
        w.add_body(BodyDesc::dynamic("thin hull", thin).at(Vec3::new(2.0, 0.5, 0.0)))
            .unwrap();
        w.add_body(
            BodyDesc::dynamic(
                "needle",
                ShapeDesc::Capsule {
                    half_height: 1.0,
                    radius: 0.001,
                },
            )
            .at(Vec3::new(-2.0, 1.5, 0.0))
            .rotated(Quat::from_rotation_z(0.3)),
        )
        .unwrap();
        let ball = w
            .add_body(
                BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.2 })
                    .at(Vec3::new(0.0, 0.5, 0.0)),
            )
            .unwrap();
        run_checked(&mut w, 3.0, 1.0, &format!("{name} degenerate shapes"));
        let y = w.body(ball).unwrap().position.y;
        println!("{name}: ball on sliver triangles rests at y = {y}");
        assert!(
            y > 0.1,
            "{name}: the ball fell through the sliver floor (y = {y})"
        );
    }
}

/// `assets/rain_1000.ron` (1,000 mixed shapes raining into a walled pit, its defaults): no
/// contact in its first 220 steps reports a depth of 0.2 m or more. Its real overlaps stay
/// under 0.13 m as the rain lands; at step 216 a convex hull (a tetrahedron 0.5 m across)
/// touching a wall 0.4 m thick was reported 0.955 m deep along a tilted normal, through the
/// wall, for one step, until the narrow phase's depth check also bounded a depth by the
/// shapes' overlap along the reported normal (benches/RESULTS.md, "A hull reported through a
/// wall").
#[test]
fn no_contact_in_a_rain_reports_a_depth_through_a_wall() {
    let path = format!("{}/assets/rain_1000.ron", env!("CARGO_MANIFEST_DIR"));
    let scene = jostle::scene::Scene::load(path).unwrap();
    let mut w = scene.build().unwrap();
    for step in 1..=220 {
        w.step(scene.dt).unwrap();
        let deepest = w.max_penetration();
        assert!(deepest < 0.2, "step {step}: a contact {deepest} m deep");
    }
}

/// A unit box spinning at 2 rad/s dropped 0.5 m onto the ground settles as the same box of
/// 1 kg does, at every mass up to `jostle::MAX_MASS`, in both resolvers: at rest on a face
/// after 200 steps, no body quarantined, never more kinetic energy than it started with plus
/// the drop's. The contacts' matrices of inverse masses left f32's normal range: the soft step
/// froze every box of 8·10¹⁹ kg or more at its first step (its friction NaN), and the Millington
/// resolver's box of 10¹⁶ kg gained a fifth of its energy and never settled, of 10²⁴ kg slid on
/// without friction (benches/RESULTS.md, "Masses up to the limit").
#[test]
fn boxes_up_to_the_mass_limit_settle_as_a_one_kilogram_box() {
    let mut wrong = Vec::new();
    for (name, r) in resolvers() {
        for mass in [1.0f32, 1e6, 1e13, 1e16, 1e19, 1e20, 1e22, jostle::MAX_MASS] {
            let mut w = world(&r);
            ground(&mut w, Vec3::ZERO);
            let h = w
                .add_body(
                    BodyDesc::dynamic(
                        "box",
                        ShapeDesc::Cuboid {
                            half_extents: Vec3::splat(0.5),
                        },
                    )
                    .at(Vec3::new(0.0, 1.0, 0.0))
                    .with_mass(mass)
                    .moving(Vec3::ZERO, Vec3::new(0.0, 2.0, 0.0)),
                )
                .unwrap();
            let start = w.kinetic_energy() + f64::from(mass) * 9.81 * 0.5;
            let (mut most, mut quarantined) = (0.0f64, 0usize);
            for _ in 0..200 {
                let report = w.step(DT).unwrap();
                quarantined += report.quarantined.len();
                most = most.max(w.kinetic_energy());
            }
            let b = w.body(h).unwrap();
            let (height, speed) = (
                b.position.y,
                b.linear_velocity.length() + b.angular_velocity.length(),
            );
            let case = format!(
                "{name}, {mass:e} kg: height {height}, speed {speed}, energy at most {:.3} of the start, {quarantined} quarantined",
                most / start
            );
            println!("{case}");
            if !(quarantined == 0
                && (height - 0.5).abs() < 1e-3
                && speed < 1e-3
                && most <= start * 1.001)
            {
                wrong.push(case);
            }
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}
