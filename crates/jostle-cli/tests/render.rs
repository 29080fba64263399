//! `jostle run --render`: PNG and GIF output end to end, and the errors of bad flags.

use image::AnimationDecoder;
use image::codecs::gif::GifDecoder;
use std::io::BufReader;
use std::path::PathBuf;
use std::process::{Command, Output};

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("jostle-render-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A ball dropped from 3 m onto the ground, with a fixed camera, in a file of its own per
/// test (`tag`): tests run in parallel, and one rewriting a shared file while another read it
/// made the reader fail now and then.
fn drop_scene(tag: &str) -> PathBuf {
    let path = temp(&format!("drop-{tag}.ron"));
    std::fs::write(
        &path,
        "Scene(name: \"drop\", steps: 40, camera: Camera(position: (0.0, 2.0, 8.0), target: (0.0, 1.5, 0.0)), bodies: [
            Body(name: \"ground\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true),
            Body(name: \"ball\", shape: Ball(radius: 0.5), position: (0.0, 3.0, 0.0)),
        ])",
    )
    .unwrap();
    path
}

fn jostle(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_jostle"))
        .args(args)
        .output()
        .unwrap()
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn gif_frames(path: &PathBuf) -> Vec<image::Frame> {
    let file = BufReader::new(std::fs::File::open(path).unwrap());
    GifDecoder::new(file)
        .unwrap()
        .into_frames()
        .collect_frames()
        .unwrap()
}

#[test]
fn png_of_the_last_frame_at_the_requested_size() {
    let (scene, png) = (drop_scene("png"), temp("last.png"));
    let out = jostle(&[
        "run",
        scene.to_str().unwrap(),
        "--render",
        png.to_str().unwrap(),
        "--size",
        "200x150",
        "--contacts",
    ]);
    ok(&out);
    let image = image::open(&png).unwrap();
    assert_eq!((image.width(), image.height()), (200, 150));
    assert!(String::from_utf8_lossy(&out.stderr).contains("wrote"));
}

#[test]
fn gif_frame_count_follows_frame_every_and_fps() {
    let scene = drop_scene("gif");
    // Explicit K: the states after steps 0, 10, 20, 30, 40.
    let gif = temp("every10.gif");
    ok(&jostle(&[
        "run",
        scene.to_str().unwrap(),
        "--render",
        gif.to_str().unwrap(),
        "--size",
        "96x72",
        "--frame-every",
        "10",
    ]));
    let frames = gif_frames(&gif);
    assert_eq!(frames.len(), 5);
    for pair in frames.windows(2) {
        assert_ne!(
            pair[0].buffer(),
            pair[1].buffer(),
            "the ball falls between frames"
        );
    }
    // Default K at 30 fps and dt = 1/60 is 2: 40 steps give 21 frames.
    let gif = temp("default.gif");
    ok(&jostle(&[
        "run",
        scene.to_str().unwrap(),
        "--render",
        gif.to_str().unwrap(),
        "--size",
        "64x48",
    ]));
    assert_eq!(gif_frames(&gif).len(), 21);
    // At 10 fps K is 6: steps 0, 6, ..., 36.
    let gif = temp("fps10.gif");
    ok(&jostle(&[
        "run",
        scene.to_str().unwrap(),
        "--render",
        gif.to_str().unwrap(),
        "--size",
        "64x48",
        "--fps",
        "10",
    ]));
    let frames = gif_frames(&gif);
    assert_eq!(frames.len(), 7);
    let (num, den) = frames[0].delay().numer_denom_ms();
    assert_eq!(num / den, 100);
}

#[test]
fn bad_render_flags_fail_with_a_clear_message() {
    let scene = drop_scene("flags");
    let s = scene.to_str().unwrap();
    let jpg = temp("x.jpg");
    let gif = temp("x.gif");
    let png = temp("x.png");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["run", s, "--render", jpg.to_str().unwrap()], ".jpg"),
        (
            vec![
                "run",
                s,
                "--render",
                png.to_str().unwrap(),
                "--size",
                "640by480",
            ],
            "--size",
        ),
        (
            vec![
                "run",
                s,
                "--render",
                png.to_str().unwrap(),
                "--size",
                "0x480",
            ],
            "width",
        ),
        (
            vec![
                "run",
                s,
                "--render",
                gif.to_str().unwrap(),
                "--frame-every",
                "0",
            ],
            "--frame-every",
        ),
        (
            vec!["run", s, "--render", gif.to_str().unwrap(), "--fps", "0"],
            "fps",
        ),
        (vec!["run", s, "--fps", "10"], "--render"),
    ];
    for (args, needle) in cases {
        let out = jostle(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} must fail");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    let bad_camera = temp("badcam.ron");
    std::fs::write(&bad_camera, "Scene(camera: Camera(fov: 190.0))").unwrap();
    let out = jostle(&[
        "run",
        bad_camera.to_str().unwrap(),
        "--render",
        png.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("camera.fov"));
}
