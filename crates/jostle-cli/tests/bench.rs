//! `jostle bench` end to end on tiny scenes: the CSV's columns, finite metrics, both plots.

use std::path::PathBuf;
use std::process::Command;

fn temp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("jostle-bench-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `jostle bench` with `args`; it must succeed.
fn bench(args: &[&std::ffi::OsStr]) -> std::process::Output {
    let out = Command::new(env!("CARGO_BIN_EXE_jostle"))
        .arg("bench")
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

const HEADER: [&str; 14] = [
    "scene",
    "resolver",
    "setting",
    "dt",
    "frames",
    "ms_per_step",
    "ms_per_60hz_step",
    "drift_m",
    "max_penetration_m",
    "mean_penetration_m",
    "energy_error",
    "time_to_sleep_s",
    "analytic_error",
    "quarantined",
];

#[test]
fn bench_writes_csv_with_finite_metrics_and_both_plots() {
    let dir = temp_dir();
    // A box resting on the ground (it falls asleep: time to sleep), and a box spinning in
    // zero gravity (a closed system: energy error).
    let rest = dir.join("rest.ron");
    std::fs::write(
        &rest,
        "Scene(name: \"tiny rest\", steps: 120, bodies: [\
           Body(name: \"ground\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true),\
           Body(name: \"box\", shape: Cuboid(half_extents: (0.5, 0.5, 0.5)), position: (0.0, 0.5, 0.0))])",
    )
    .unwrap();
    let spin = dir.join("spin.ron");
    std::fs::write(
        &spin,
        "Scene(name: \"tiny spin\", steps: 60, gravity: (0.0, 0.0, 0.0), bodies: [\
           Body(name: \"box\", shape: Cuboid(half_extents: (0.5, 0.25, 0.1)), angular_velocity: (0.0, 3.0, 0.0), can_sleep: false)])",
    )
    .unwrap();
    // A ball in free fall for 1 s that declares its closed form: the analytic error.
    let fall = dir.join("fall.ron");
    std::fs::write(
        &fall,
        "Scene(name: \"tiny fall\", steps: 60, analytic: FreeFall(body: \"ball\"), bodies: [\
           Body(name: \"ball\", shape: Ball(radius: 0.5), position: (0.0, 10.0, 0.0), can_sleep: false)])",
    )
    .unwrap();
    let out_dir = dir.join("out");
    let out = bench(&[
        rest.as_os_str(),
        spin.as_os_str(),
        fall.as_os_str(),
        "--sweep".as_ref(),
        "substeps".as_ref(),
        "--settle".as_ref(),
        "0.5".as_ref(),
        "--out".as_ref(),
        out_dir.as_os_str(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("tiny rest") && stdout.contains("soft-step"),
        "{stdout}"
    );

    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap().split(',').collect::<Vec<_>>(), HEADER);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // 3 scenes × 2 resolvers × 4 substep settings.
    assert_eq!(rows.len(), 24, "{csv}");
    let col = |name: &str| HEADER.iter().position(|h| *h == name).unwrap();
    for row in &rows {
        assert_eq!(row.len(), HEADER.len(), "{row:?}");
        assert_eq!(row[col("quarantined")], "0", "{row:?}");
        let (spin, fall) = (row[0] == "tiny spin", row[0] == "tiny fall");
        for (i, field) in row.iter().enumerate().skip(3) {
            // Energy error applies to the closed systems only (no fixed body), time to sleep to
            // the resting box, analytic error to the scene that declares its closed form.
            let applies = match HEADER[i] {
                "energy_error" => spin || fall,
                "time_to_sleep_s" => !spin && !fall,
                "analytic_error" => fall,
                _ => true,
            };
            if applies {
                let x: f64 = field
                    .parse()
                    .unwrap_or_else(|e| panic!("{}: `{field}`: {e}", HEADER[i]));
                assert!(x.is_finite() && x >= 0.0, "{} = {x} in {row:?}", HEADER[i]);
            } else {
                assert!(field.is_empty(), "{} = `{field}` in {row:?}", HEADER[i]);
            }
        }
        assert!(row[col("ms_per_step")].parse::<f64>().unwrap() > 0.0);
        if fall {
            // Semi-implicit Euler falls ½·g·t·h ahead of y₀ − ½gt² (h the integration step:
            // 1/60 s, or less with substeps): 0.0818 m after 1 s at h = 1/60, never more.
            let e: f64 = row[col("analytic_error")].parse().unwrap();
            assert!(
                e > 1e-4 && e < 0.0818 * 1.01,
                "free-fall analytic error {e} in {row:?}"
            );
        }
    }
    // The free fall's analytic error shrinks with the step: Millington's substeps are world
    // steps of dt/n, so 8 of them leave an eighth of the error of 1; so do the soft step's.
    // The soft step's substeps are its own (its defaults' 8 substeps, as a scene that names
    // no resolver gets them, were run at every level of the sweep: the sweep's setting was
    // dropped as an override of the scene's own resolver).
    let fall_error = |resolver: &str, setting: &str| -> f64 {
        rows.iter()
            .find(|r| r[0] == "tiny fall" && r[1] == resolver && r[2] == setting)
            .unwrap_or_else(|| panic!("no {resolver} {setting} row for tiny fall"))
            [col("analytic_error")]
        .parse()
        .unwrap()
    };
    for resolver in ["millington", "soft-step"] {
        let one = fall_error(resolver, "substeps=1");
        let eight = fall_error(resolver, "substeps=8");
        assert!(
            (eight * 8.0 - one).abs() < 0.02 * one,
            "{resolver}: analytic error at 1 substep {one}, at 8 substeps {eight}"
        );
    }

    for stem in ["tiny_rest", "tiny_spin", "tiny_fall"] {
        for ext in ["svg", "png"] {
            let p = out_dir.join(format!("{stem}.{ext}"));
            let len = std::fs::metadata(&p)
                .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
                .len();
            assert!(len > 1000, "{} is only {len} bytes", p.display());
        }
    }
    let png = image::open(out_dir.join("tiny_rest.png")).unwrap();
    assert_eq!((png.width(), png.height()), (800, 560));
}

/// Two files whose scenes share a name get a plot each and rows told apart by file: before,
/// both files' rows went into one plot under one name, and results.csv could not say which
/// row came from which file.
#[test]
fn scenes_of_the_same_name_from_two_files_are_kept_apart() {
    let dir = temp_dir().join("same-name");
    let (a, b) = (dir.join("a"), dir.join("b"));
    for (d, height) in [(&a, 1.0), (&b, 5.0)] {
        std::fs::create_dir_all(d).unwrap();
        std::fs::write(
            d.join("drop.ron"),
            format!(
                "Scene(name: \"drop\", steps: 30, bodies: [\
                   Body(name: \"ground\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true),\
                   Body(name: \"ball\", shape: Ball(radius: 0.5), position: (0.0, {height}, 0.0))])"
            ),
        )
        .unwrap();
    }
    let out_dir = dir.join("out");
    let (first, second) = (a.join("drop.ron"), b.join("drop.ron"));
    bench(&[
        first.as_os_str(),
        second.as_os_str(),
        "--resolver".as_ref(),
        "soft-step".as_ref(),
        "--out".as_ref(),
        out_dir.as_os_str(),
    ]);
    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    let scenes: Vec<&str> = csv
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').next())
        .collect();
    assert_eq!(scenes.len(), 2, "{csv}");
    assert!(
        scenes[0] != scenes[1] && scenes.iter().all(|s| s.contains("drop.ron")),
        "{csv}"
    );
    let pngs = std::fs::read_dir(&out_dir)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "png"))
        })
        .count();
    assert_eq!(pngs, 2, "one plot per file");
}

/// A scene that is one of the bench's own outputs is refused before any run, and loses
/// nothing: a scene saved as `OUT/results.csv`, or as the plot its name gives (`OUT/drop.svg`),
/// was replaced by the results and the bench exited 0.
#[test]
fn a_scene_among_the_outputs_is_refused_and_kept() {
    let dir = temp_dir().join("own-input");
    std::fs::create_dir_all(&dir).unwrap();
    let text = "Scene(name: \"drop\", steps: 10, bodies: [\
                  Body(name: \"ground\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true),\
                  Body(name: \"ball\", shape: Ball(radius: 0.5), position: (0.0, 1.0, 0.0))])";
    for name in ["results.csv", "drop.svg", "drop.png"] {
        let scene = dir.join(name);
        std::fs::write(&scene, text).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_jostle"))
            .args(["bench", "--resolver", "soft-step", "--out"])
            .arg(&dir)
            .arg(&scene)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name}: accepted");
        assert!(stderr.contains("is the scene"), "{name}: {stderr}");
        assert_eq!(std::fs::read_to_string(&scene).unwrap(), text, "{name}");
        std::fs::remove_file(&scene).unwrap();
    }
}

/// A scene without a name gets `unnamed.svg` and `.png` inside the output directory: its
/// plots were written beside it as `OUT.svg` and `OUT.png`, and with `--out .` the bench
/// failed after every run.
#[test]
fn a_scene_without_a_name_plots_inside_the_output_directory() {
    let dir = temp_dir().join("no-name");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("noname.ron");
    std::fs::write(
        &scene,
        "Scene(name: \"\", steps: 10, bodies: [\
           Body(name: \"ground\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true),\
           Body(name: \"ball\", shape: Ball(radius: 0.5), position: (0.0, 1.0, 0.0))])",
    )
    .unwrap();
    let out_dir = dir.join("out");
    bench(&[
        scene.as_os_str(),
        "--resolver".as_ref(),
        "soft-step".as_ref(),
        "--out".as_ref(),
        out_dir.as_os_str(),
    ]);
    for ext in ["svg", "png"] {
        assert!(out_dir.join(format!("unnamed.{ext}")).is_file(), "{ext}");
        assert!(
            !dir.join(format!("out.{ext}")).exists(),
            "{ext} beside --out"
        );
    }
}
