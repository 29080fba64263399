//! Rendered images checked against geometry: a unit cube on the ground seen from a fixed
//! camera, projected independently of the renderer; the grid; state tints; GIF frames.

use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};
use jostle_render::image::codecs::gif::GifDecoder;
use jostle_render::image::{AnimationDecoder, Rgb, RgbImage};
use jostle_render::{Camera, GifWriter, RenderSettings, Renderer};
use std::io::Cursor;

const W: u32 = 320;
const H: u32 = 240;

fn camera() -> Camera {
    Camera {
        position: Vec3::new(3.0, 2.5, 5.0),
        target: Vec3::new(0.0, 0.5, 0.0),
        fov_degrees: 45.0,
    }
}

fn settings() -> RenderSettings {
    RenderSettings {
        width: W,
        height: H,
        camera: Some(camera()),
        contacts: false,
    }
}

fn ground_only() -> World {
    let mut world = World::new(WorldSettings::default());
    world
        .add_body(BodyDesc::fixed(
            "ground",
            ShapeDesc::HalfSpace { normal: Vec3::Y },
        ))
        .unwrap();
    world
}

/// One unit cube resting on the ground, centred at (0, 0.5, 0).
fn cube_on_ground() -> (World, jostle::BodyHandle) {
    let mut world = ground_only();
    let cube = world
        .add_body(
            BodyDesc::dynamic(
                "cube",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.5),
                },
            )
            .at(Vec3::new(0.0, 0.5, 0.0)),
        )
        .unwrap();
    (world, cube)
}

/// The pixel a world point falls in, by the textbook look-at and pinhole projection, written
/// here independently of the renderer.
fn pixel_of(p: Vec3) -> (u32, u32) {
    let c = camera();
    let forward = (c.target - c.position).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let r = p - c.position;
    let (x, y, z) = (r.dot(right), r.dot(up), r.dot(forward));
    let focal = H as f32 / 2.0 / (c.fov_degrees.to_radians() / 2.0).tan();
    let px = W as f32 / 2.0 + focal * x / z;
    let py = H as f32 / 2.0 - focal * y / z;
    (px as u32, py as u32)
}

fn at(img: &RgbImage, p: Vec3) -> Rgb<u8> {
    let (x, y) = pixel_of(p);
    *img.get_pixel(x, y)
}

#[test]
fn the_cube_is_where_geometry_puts_it() {
    let (world, _) = cube_on_ground();
    let image = Renderer::new(settings()).unwrap().render(&world);
    let background = Renderer::new(settings()).unwrap().render(&ground_only());
    assert_eq!(image.dimensions(), (W, H));

    // Inside the silhouette: the centre, and points just inside the visible faces.
    let inside = [
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::new(0.0, 0.98, 0.0),  // top face
        Vec3::new(0.3, 0.3, 0.5),   // front face
        Vec3::new(0.5, 0.7, -0.3),  // right face
        Vec3::new(-0.4, 0.1, 0.49), // near the front-left bottom corner
    ];
    for p in inside {
        assert_ne!(at(&image, p), at(&background, p), "{p} must show the cube");
    }
    // Clearly outside: ground around it and sky above it, identical to the empty scene.
    let outside = [
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(1.5, 0.0, 0.0),
        Vec3::new(-1.5, 0.0, 0.5),
        Vec3::new(0.0, 0.0, 1.5),
        Vec3::new(-1.2, 1.2, 0.0),
    ];
    for p in outside {
        assert_eq!(
            at(&image, p),
            at(&background, p),
            "{p} must not show the cube"
        );
    }
    // The three visible faces are shaded differently (Lambert from one sun).
    let faces = [
        at(&image, Vec3::new(0.0, 0.98, 0.0)),
        at(&image, Vec3::new(0.0, 0.5, 0.5)),
        at(&image, Vec3::new(0.5, 0.5, 0.0)),
    ];
    assert!(
        faces[0] != faces[1] && faces[1] != faces[2] && faces[0] != faces[2],
        "{faces:?}"
    );
}

#[test]
fn the_ground_grid_is_drawn_below_the_horizon() {
    let image = Renderer::new(settings()).unwrap().render(&ground_only());
    let brightness = |p: &Rgb<u8>| p.0.iter().map(|&c| c as u32).sum::<u32>();
    // The row through the ground point (0, 0, 2): ground pixels and darker grid-line pixels.
    let (_, row) = pixel_of(Vec3::new(0.0, 0.0, 2.0));
    let values: Vec<u32> = (0..W)
        .map(|x| brightness(image.get_pixel(x, row)))
        .collect();
    let ground = *values.iter().max().unwrap();
    let lines = values.iter().filter(|&&v| v + 60 < ground).count();
    assert!(lines >= 4, "grid-line pixels on row {row}: {lines}");
    assert!(lines < W as usize / 2, "the ground shows between the lines");
    // A grid line passes under the point (1, 0, 2): x = 1 is a multiple of 1 m.
    let (x, y) = pixel_of(Vec3::new(1.0, 0.0, 2.0));
    let on_line =
        (x.saturating_sub(1)..=x + 1).any(|x| brightness(image.get_pixel(x, y)) + 60 < ground);
    assert!(on_line, "the line x = 1 m at ({x}, {y})");
    // The top row is sky: one smooth colour, no lines.
    let top: Vec<u32> = (0..W).map(|x| brightness(image.get_pixel(x, 0))).collect();
    assert!(top.iter().max().unwrap() - top.iter().min().unwrap() < 4);
}

#[test]
fn sleeping_and_fixed_bodies_get_their_tints() {
    let (mut world, cube) = cube_on_ground();
    let centre = Vec3::new(0.0, 0.5, 0.5);
    let awake = at(&Renderer::new(settings()).unwrap().render(&world), centre);
    world.sleep(cube).unwrap();
    let asleep = at(&Renderer::new(settings()).unwrap().render(&world), centre);
    assert_ne!(awake, asleep);
    let spread = |p: Rgb<u8>| p.0.iter().max().unwrap() - p.0.iter().min().unwrap();
    assert!(
        spread(asleep) < spread(awake),
        "sleeping is desaturated: {awake:?} {asleep:?}"
    );

    let mut fixed = ground_only();
    fixed
        .add_body(
            BodyDesc::fixed(
                "block",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.5),
                },
            )
            .at(Vec3::new(0.0, 0.5, 0.0)),
        )
        .unwrap();
    let grey = at(&Renderer::new(settings()).unwrap().render(&fixed), centre);
    assert_eq!(spread(grey), 0, "fixed bodies are grey: {grey:?}");
}

#[test]
fn contacts_are_drawn_on_request() {
    let (mut world, _) = cube_on_ground();
    world.step(1.0 / 60.0).unwrap();
    assert!(!world.contacts().is_empty());
    let plain = Renderer::new(settings()).unwrap().render(&world);
    let with = Renderer::new(RenderSettings {
        contacts: true,
        ..settings()
    })
    .unwrap()
    .render(&world);
    let changed = plain
        .pixels()
        .zip(with.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert!(changed > 10, "{changed} pixels show contacts");
}

#[test]
fn the_default_camera_frames_the_scene() {
    let (world, _) = cube_on_ground();
    let mut renderer = Renderer::new(RenderSettings {
        width: W,
        height: H,
        ..Default::default()
    })
    .unwrap();
    let image = renderer.render(&world);
    let cam = *renderer.camera().expect("chosen at the first frame");
    assert!(cam.position.y > cam.target.y, "seen from above");
    // The cube's centre is drawn near the middle of the image.
    let centre = *image.get_pixel(W / 2, H / 2);
    let empty = Renderer::new(RenderSettings {
        camera: Some(cam),
        width: W,
        height: H,
        contacts: false,
    })
    .unwrap()
    .render(&ground_only());
    assert_ne!(centre, *empty.get_pixel(W / 2, H / 2));
}

#[test]
fn bad_settings_are_errors() {
    for s in [
        RenderSettings {
            width: 0,
            ..settings()
        },
        RenderSettings {
            height: 100_000,
            ..settings()
        },
        RenderSettings {
            camera: Some(Camera {
                fov_degrees: 180.0,
                ..camera()
            }),
            ..settings()
        },
        RenderSettings {
            camera: Some(Camera {
                target: camera().position,
                ..camera()
            }),
            ..settings()
        },
    ] {
        assert!(Renderer::new(s).is_err(), "{s:?}");
    }
    assert!(GifWriter::new(Vec::new(), 0).is_err());
}

#[test]
fn a_gif_has_one_frame_per_kth_step_and_shows_the_fall() {
    let mut world = ground_only();
    world
        .add_body(
            BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.5 }).at(Vec3::new(0.0, 3.0, 0.0)),
        )
        .unwrap();
    let mut renderer = Renderer::new(RenderSettings {
        width: 96,
        height: 72,
        camera: Some(Camera {
            position: Vec3::new(0.0, 2.0, 8.0),
            target: Vec3::new(0.0, 1.5, 0.0),
            fov_degrees: 45.0,
        }),
        contacts: false,
    })
    .unwrap();
    let (steps, every) = (45u64, 10u64);
    let mut gif = GifWriter::new(Vec::new(), 30).unwrap();
    gif.push(renderer.render(&world)).unwrap();
    for step in 1..=steps {
        world.step(1.0 / 60.0).unwrap();
        if step % every == 0 {
            gif.push(renderer.render(&world)).unwrap();
        }
    }
    assert_eq!(gif.frames(), 5);
    let bytes = gif.finish().unwrap();
    let frames = GifDecoder::new(Cursor::new(bytes))
        .unwrap()
        .into_frames()
        .collect_frames()
        .unwrap();
    assert_eq!(frames.len(), (steps / every + 1) as usize);
    for pair in frames.windows(2) {
        assert_eq!(pair[0].buffer().dimensions(), (96, 72));
        assert_ne!(
            pair[0].buffer(),
            pair[1].buffer(),
            "the ball moves between frames"
        );
    }
    let (num, den) = frames[0].delay().numer_denom_ms();
    assert_eq!(
        num / den,
        30,
        "30 fps is 3 hundredths of a second per frame"
    );
}

#[test]
fn scene_cameras_are_validated_and_converted() {
    use jostle::scene::Scene;
    let scene = |camera: &str| Scene::parse(&format!("Scene(camera: {camera})"), "cam.ron");
    let ok =
        scene("Camera(position: (1.0, 2.0, 3.0), target: (0.0, 1.0, 0.0), fov: 50.0)").unwrap();
    let cam = Camera::from(ok.camera.as_ref().unwrap());
    assert_eq!(
        (cam.position, cam.fov_degrees),
        (Vec3::new(1.0, 2.0, 3.0), 50.0)
    );
    let defaults = scene("Camera()").unwrap().camera.unwrap();
    assert_eq!((defaults.target, defaults.fov), (Vec3::ZERO, 45.0));
    for (text, field) in [
        ("Camera(fov: 180.0)", "camera.fov"),
        ("Camera(fov: 0.5)", "camera.fov"),
        ("Camera(position: (0.0, 0.0, 0.0))", "camera.target"),
        ("Camera(target: (1.0, inf, 0.0))", "camera.target"),
    ] {
        let err = scene(text).expect_err(text).to_string();
        assert!(
            err.contains(field) && err.contains("cam.ron"),
            "{text}: {err}"
        );
    }
}
