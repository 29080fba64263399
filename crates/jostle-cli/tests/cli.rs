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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
    let dt = 1.0f64 / 60.0;
    for r in &rows {
        assert_eq!(r.len(), 17);
        assert_eq!(r[2], "b");
        let n: f64 = r[0].parse().unwrap();
        let y: f64 = r[4].parse().unwrap();
        let expected = 50.0 - 9.81 * dt * dt * n * (n + 1.0) / 2.0;
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
