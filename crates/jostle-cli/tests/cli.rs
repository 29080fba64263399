//! The `jostle` command end to end: traces, JSON summaries, errors.

use std::path::PathBuf;
use std::process::Command;

fn jostle() -> Command {
    Command::new(env!("CARGO_BIN_EXE_jostle"))
}

fn asset(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets")
        .join(name)
}

/// Asserts that the command succeeded, showing its stderr when it did not.
fn assert_ok(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("jostle-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn trace_of_a_free_fall_follows_semi_implicit_euler() {
    let scene = temp("fall.ron");
    std::fs::write(&scene, "Scene(name: \"fall\", steps: 90, bodies: [Body(name: \"b\", shape: Ball(radius: 0.1), position: (0.0, 50.0, 0.0))])").unwrap();
    let trace = temp("fall.csv");
    let out = jostle()
        .arg("run")
        .arg(&scene)
        .arg("--trace")
        .arg(&trace)
        .arg("--every")
        .arg("7")
        .output()
        .unwrap();
    assert_ok(&out);
    let text = std::fs::read_to_string(&trace).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("step,time,body,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz,awake")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let steps: Vec<u64> = rows.iter().map(|r| r[0].parse().unwrap()).collect();
    let mut expected: Vec<u64> = (0..=90).filter(|s| s % 7 == 0).collect();
    expected.push(90);
    assert_eq!(steps, expected, "step 0, every 7th, and the last");
    // The default resolver (the soft step) integrates in substeps of h = dt / substeps.
    let substeps = jostle::SoftStepSettings::default().substeps as f64;
    let h = 1.0f64 / 60.0 / substeps;
    for r in &rows {
        assert_eq!(r.len(), 17);
        assert_eq!(r[2], "b");
        let n: f64 = r[0].parse::<f64>().unwrap() * substeps;
        let y: f64 = r[4].parse().unwrap();
        let expected = 50.0 - 9.81 * h * h * n * (n + 1.0) / 2.0;
        assert!((y - expected).abs() < 1e-3, "step {n}: y {y} vs {expected}");
        assert_eq!(r[16], "1");
    }
}

#[test]
fn json_is_one_object_on_stdout() {
    let out = jostle()
        .args(["run", "--json", "--steps", "30"])
        .arg(asset("box_drop.ron"))
        .output()
        .unwrap();
    assert_ok(&out);
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.trim().lines().count(), 1);
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    for key in [
        "scene",
        "resolver",
        "steps",
        "dt",
        "bodies",
        "ms_per_step",
        "max_penetration",
        "kinetic_energy_initial",
        "kinetic_energy_final",
        "awake_final",
        "all_asleep_step",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["scene"], "box drop");
    assert_eq!(v["steps"], 30);
    assert_eq!(v["bodies"], 2);
}

#[test]
fn json_reports_the_contact_rows_solved_directly() {
    // A light box under a 1,000 times heavier one is an island the soft step solves
    // directly; a single box is not.
    let direct_rows = |file: &str| {
        let out = jostle()
            .args(["run", "--json", "--steps", "30"])
            .arg(asset(file))
            .output()
            .unwrap();
        assert_ok(&out);
        let v: serde_json::Value =
            serde_json::from_str(String::from_utf8(out.stdout).unwrap().trim()).unwrap();
        v["direct_rows_per_step"].as_f64().unwrap()
    };
    assert!(direct_rows("mass_ratio_1000.ron") > 0.0);
    assert_eq!(direct_rows("box_drop.ron"), 0.0);
}

#[test]
fn errors_exit_non_zero_with_the_message() {
    let bad = temp("bad.ron");
    std::fs::write(
        &bad,
        "Scene(bodies: [Body(name: \"x\", shape: Ball(radius: -1.0))])",
    )
    .unwrap();
    let out = jostle().arg("run").arg(&bad).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.ron") && err.contains("\"x\"") && err.contains("radius"),
        "{err}"
    );

    let out = jostle()
        .args(["run", "--resolver", "nope"])
        .arg(asset("box_drop.ron"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("millington"));

    let out = jostle().args(["run", "no/such/file.ron"]).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no/such/file.ron"));
}

#[test]
fn the_summary_table_names_every_figure() {
    let out = jostle()
        .args(["run", "--steps", "20"])
        .arg(asset("box_drop.ron"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let s = String::from_utf8(out.stdout).unwrap();
    for key in [
        "bodies",
        "ms/step",
        "broad",
        "narrow",
        "resolve",
        "kinetic energy start",
        "largest penetration",
        "awake",
    ] {
        assert!(s.contains(key), "missing {key} in\n{s}");
    }
}

/// Every kind of bad input the command can be given: it exits non-zero, prints a message on
/// stderr naming what is wrong (file, line:column, body, field or flag), and never panics.
#[test]
fn every_bad_input_exits_non_zero_with_a_precise_message() {
    let body = |fields: &str| format!("Scene(bodies: [Body(name: \"culprit\", {fields})])");
    let cases: Vec<(&str, String, Vec<&str>, &[&str])> = vec![
        (
            "malformed RON",
            "Scene(bodies: [Body(name: \"a\", shape: Ball(radius: 1.0)]".into(),
            vec![],
            &["bad.ron:1:"],
        ),
        (
            "wrong type",
            body("shape: Ball(radius: \"big\")"),
            vec![],
            &["bad.ron:1:", "culprit"],
        ),
        (
            "unknown field",
            body("shape: Ball(radius: 1.0), colour: 2"),
            vec![],
            &["colour", "culprit"],
        ),
        (
            "missing shape",
            body("position: (0.0, 1.0, 0.0)"),
            vec![],
            &["shape"],
        ),
        (
            "NaN",
            body("shape: Ball(radius: 1.0), position: (NaN, 0.0, 0.0)"),
            vec![],
            &["culprit", "position"],
        ),
        (
            "infinity",
            body("shape: Ball(radius: inf)"),
            vec![],
            &["culprit", "radius"],
        ),
        (
            "negative mass",
            body("shape: Ball(radius: 1.0), mass: -1.0"),
            vec![],
            &["culprit", "mass"],
        ),
        (
            "zero mass",
            body("shape: Ball(radius: 1.0), mass: 0.0"),
            vec![],
            &["culprit", "mass"],
        ),
        (
            "zero density",
            body("shape: Ball(radius: 1.0), density: 0.0"),
            vec![],
            &["culprit", "density"],
        ),
        (
            "zero size",
            body("shape: Cuboid(half_extents: (1.0, 0.0, 1.0))"),
            vec![],
            &["culprit", "half_extents"],
        ),
        (
            "zero normal",
            body("shape: HalfSpace(normal: (0.0, 0.0, 0.0)), fixed: true"),
            vec![],
            &["culprit", "normal"],
        ),
        (
            "empty mesh",
            body("shape: TriMesh(vertices: [], indices: []), fixed: true"),
            vec![],
            &["culprit", "shape."],
        ),
        (
            "mesh index out of range",
            body(
                "shape: TriMesh(vertices: [(0.0,0.0,0.0),(1.0,0.0,0.0),(0.0,0.0,1.0)], indices: [(0, 1, 9)]), fixed: true",
            ),
            vec![],
            &["culprit", "indices"],
        ),
        (
            "degenerate hull",
            body("shape: ConvexHull(points: [(0.0,0.0,0.0),(1.0,0.0,0.0),(2.0,0.0,0.0)])"),
            vec![],
            &["culprit", "points"],
        ),
        (
            "negative dt in the scene",
            "Scene(dt: -0.01)".into(),
            vec![],
            &["dt"],
        ),
        (
            "spin on a body with locked rotation",
            body(
                "shape: Ball(radius: 1.0), lock_rotation: true, angular_velocity: (0.0, 1.0, 0.0)",
            ),
            vec![],
            &["culprit", "angular_velocity", "lock_rotation"],
        ),
        (
            "soft-step setting out of range",
            "Scene(resolver: SoftStep(contact_hertz: -30.0))".into(),
            vec![],
            &["resolver.contact_hertz", "-30"],
        ),
        (
            "zero-hertz soft contacts",
            "Scene(resolver: SoftStep(static_hertz: 0.0))".into(),
            vec![],
            &["resolver.static_hertz", "> 0"],
        ),
        (
            "Millington relaxation out of range",
            "Scene(resolver: Millington(relaxation: -1.0))".into(),
            vec![],
            &["resolver.relaxation", "-1"],
        ),
        (
            "Millington angular limit negative",
            "Scene(resolver: Millington(angular_limit: -1.0))".into(),
            vec![],
            &["resolver.angular_limit", "-1"],
        ),
        (
            "Millington velocity budget of zero picks",
            "Scene(resolver: Millington(velocity_iterations: 0))".into(),
            vec![],
            &["resolver.velocity_iterations", "at least one pick"],
        ),
        (
            "negative --dt",
            "Scene()".into(),
            vec!["--dt=-1"],
            &["--dt"],
        ),
        (
            "zero --every",
            "Scene()".into(),
            vec!["--every", "0", "--trace", "never-written.csv"],
            &["--every must be at least 1"],
        ),
        (
            // Accepted and ignored before, unlike --fps or --frame-every without --render.
            "--every without --trace",
            "Scene()".into(),
            vec!["--every", "5"],
            &["--trace"],
        ),
        (
            "unknown resolver",
            "Scene()".into(),
            vec!["--resolver", "nope"],
            &["nope", "millington"],
        ),
    ];
    for (i, (what, text, flags, needles)) in cases.into_iter().enumerate() {
        // bad.ron: the message must name the file; one directory per case, no sharing.
        let file = temp(&format!("case{i}")).join("bad.ron");
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(&file, &text).unwrap();
        let out = jostle()
            .arg("run")
            .args(&flags)
            .arg(&file)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{what}: accepted");
        assert!(out.status.code().is_some(), "{what}: killed by a signal");
        assert!(!err.contains("panicked"), "{what}: panicked: {err}");
        for n in needles {
            assert!(err.contains(n), "{what}: message lacks `{n}`: {err}");
        }
    }
}

/// `jostle run SCENE --steps N --snapshot FILE` then `jostle run FILE --steps M` writes, row
/// for row and bit for bit, the trace of `jostle run SCENE --steps N+M` from step N on
/// (warm-start impulses, manifolds and sleep state included).
#[test]
fn a_snapshot_continues_the_trace_bit_for_bit() {
    let dir = temp("snapshot");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = asset("determinism.ron");
    let run = |args: &[&std::ffi::OsStr]| {
        let out = jostle().arg("run").args(args).output().unwrap();
        assert_ok(&out);
    };
    let (whole, first, second, snap) = (
        dir.join("whole.csv"),
        dir.join("first.csv"),
        dir.join("second.csv"),
        dir.join("state.ron"),
    );
    run(&[
        scene.as_os_str(),
        "--steps".as_ref(),
        "400".as_ref(),
        "--trace".as_ref(),
        whole.as_os_str(),
    ]);
    run(&[
        scene.as_os_str(),
        "--steps".as_ref(),
        "150".as_ref(),
        "--trace".as_ref(),
        first.as_os_str(),
        "--snapshot".as_ref(),
        snap.as_os_str(),
    ]);
    run(&[
        snap.as_os_str(),
        "--steps".as_ref(),
        "250".as_ref(),
        "--trace".as_ref(),
        second.as_os_str(),
    ]);
    let rows = |p: &PathBuf| -> Vec<String> {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .skip(1)
            .map(String::from)
            .collect()
    };
    let step_of = |row: &String| -> u64 { row.split(',').next().unwrap().parse().unwrap() };
    let whole = rows(&whole);
    let second = rows(&second);
    assert_eq!(
        step_of(&second[0]),
        150,
        "the continued trace starts at the snapshot's step"
    );
    let first_difference = |got: &[String], want: Vec<&String>| {
        assert_eq!(got.len(), want.len(), "row counts differ");
        if let Some((g, w)) = got.iter().zip(want).find(|(g, w)| g != w) {
            panic!("first differing row:\n got  {g}\n want {w}");
        }
    };
    first_difference(
        &second,
        whole.iter().filter(|r| step_of(r) >= 150).collect(),
    );
    // The first part is the whole run's beginning, too.
    first_difference(
        &rows(&first),
        whole.iter().filter(|r| step_of(r) <= 150).collect(),
    );
}

/// An output that is the scene itself, or another output, is refused before anything is
/// written, and a bad output loses nothing already on disk (issue 16): `--trace scene.ron`
/// used to overwrite the scene with CSV and exit 0, and `--render keep.png --trace
/// /nonexistent/t.csv` truncated keep.png to 0 bytes; `--trace /dev/stdot` failed after the
/// run.
#[test]
fn outputs_never_overwrite_the_scene_each_other_or_an_untouched_file() {
    let scene = temp("own.ron");
    let text = std::fs::read_to_string(asset("box_drop.ron")).unwrap();
    std::fs::write(&scene, &text).unwrap();
    let s = scene.to_str().unwrap();
    let keep = temp("keep.png");
    std::fs::write(&keep, b"precious").unwrap();
    let k = keep.to_str().unwrap();
    let csv = temp("same.csv");
    let c = csv.to_str().unwrap();
    let missing = "/nonexistent-jostle-dir/t.csv";
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["run", s, "--steps", "3", "--trace", s],
            "the scene being run",
        ),
        (
            vec!["run", s, "--steps", "3", "--snapshot", s],
            "the scene being run",
        ),
        (
            vec!["run", s, "--steps", "3", "--trace", c, "--render", c],
            "writes the same file",
        ),
        (
            vec!["run", s, "--steps", "3", "--render", k, "--trace", missing],
            "--trace",
        ),
        (
            vec![
                "run",
                s,
                "--steps",
                "3",
                "--snapshot",
                "/nonexistent-jostle-dir/s.ron",
            ],
            "--snapshot",
        ),
        (
            vec!["run", s, "--steps", "3", "--render", k, "--fps", "0"],
            "--fps",
        ),
        // An output named for another output's format.
        (
            vec!["run", s, "--steps", "3", "--trace", k],
            "not a .png file",
        ),
        // A device path that does not exist (a misspelt `/dev/stdout`) was tried only after
        // the whole run.
        (
            vec![
                "run",
                s,
                "--steps",
                "3",
                "--render",
                k,
                "--trace",
                "/dev/jostle-no-such-device.csv",
            ],
            "--trace",
        ),
    ];
    for (args, expect) in cases {
        let out = jostle().args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(expect), "{args:?}: {stderr}");
        assert_eq!(
            std::fs::read_to_string(&scene).unwrap(),
            text,
            "{args:?} changed the scene"
        );
        assert_eq!(
            std::fs::read(&keep).unwrap(),
            b"precious",
            "{args:?} touched keep.png"
        );
        assert!(!csv.exists(), "{args:?} wrote {c}");
    }
    // A fine run with a new output still works and leaves the scene alone.
    let out = jostle()
        .args(["run", s, "--steps", "3", "--trace", c])
        .output()
        .unwrap();
    assert_ok(&out);
    assert!(std::fs::read_to_string(&csv).unwrap().lines().count() > 1);
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
}

/// Outputs are written beside their targets and renamed into place when complete: after a
/// run nothing partial is left, and each output is whole.
#[test]
fn outputs_are_renamed_into_place_whole() {
    let dir = temp("staged");
    std::fs::create_dir_all(&dir).unwrap();
    let (trace, gif, snap) = (dir.join("t.csv"), dir.join("a.gif"), dir.join("s.ron"));
    std::fs::write(&trace, "old").unwrap();
    let out = jostle()
        .args([
            "run",
            asset("box_drop.ron").to_str().unwrap(),
            "--steps",
            "20",
        ])
        .args([
            "--trace",
            trace.to_str().unwrap(),
            "--render",
            gif.to_str().unwrap(),
        ])
        .args(["--size", "32x24", "--snapshot", snap.to_str().unwrap()])
        .output()
        .unwrap();
    assert_ok(&out);
    let rows = std::fs::read_to_string(&trace).unwrap().lines().count();
    assert!(rows > 20, "{rows} trace lines");
    assert!(std::fs::read(&gif).unwrap().starts_with(b"GIF89a"));
    assert!(
        std::fs::read_to_string(&snap)
            .unwrap()
            .contains("Snapshot(")
    );
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        names.iter().all(|n| !n.contains("jostle-partial")),
        "left behind: {names:?}"
    );
}

/// The lecture's examples through the command line: `--resolver millington` on a scene that
/// names Millington keeps the scene's settings, and the traced step gives the printed digits
/// (the second example's cube on its edge: v_y 0.6234 and ω_z 0.1715, from rounded
/// intermediates, so to ±2·10⁻⁴).
#[test]
fn the_lecture_examples_run_through_the_command_line() {
    let trace = temp("lecture_2.csv");
    let out = jostle()
        .arg("run")
        .arg(asset("lecture_2_cube_edge.ron"))
        .args(["--resolver", "millington", "--trace"])
        .arg(&trace)
        .output()
        .unwrap();
    assert_ok(&out);
    let text = std::fs::read_to_string(&trace).unwrap();
    let last: Vec<f64> = text
        .lines()
        .last()
        .unwrap()
        .split(',')
        .skip(3)
        .take(13)
        .map(|v| v.parse().unwrap())
        .collect();
    let (vx, vy, wx, wz) = (last[7], last[8], last[10], last[12]);
    assert!((vx - 2.165).abs() < 1e-4, "{text}");
    assert!((vy - 0.6234).abs() < 2e-4, "{text}");
    assert!((wz - 0.1715).abs() < 2e-4, "{text}");
    assert!(wx.abs() < 1e-5, "no spin about x: {text}");
    for file in [
        "lecture_1_spheres.ron",
        "lecture_2_cube_face.ron",
        "lecture_3_projection.ron",
    ] {
        let out = jostle()
            .arg("run")
            .arg(asset(file))
            .args(["--resolver", "millington", "--json"])
            .output()
            .unwrap();
        assert_ok(&out);
    }
}
