//! `jostle run --render`: the image or animation of a run, through `jostle-render`.
//!
//! In: the command's render flags and the scene. Out: a PNG of the last frame, or a GIF of
//! the states after steps 0, K, 2K, … (K = `--frame-every`). Everything the user typed is
//! checked before the run starts, so a bad flag never costs a simulation.

use crate::staged::Staged;
use jostle::World;
use jostle_render::{Camera, GifWriter, RenderSettings, Renderer};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// The render flags, as typed.
#[derive(Clone, Debug)]
pub struct RenderFlags {
    pub path: PathBuf,
    pub frame_every: Option<u64>,
    pub fps: u32,
    pub size: String,
    pub contacts: bool,
}

/// What the output file's extension asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Png,
    Gif,
}

fn format_of(path: &Path) -> Result<Format, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(Format::Png),
        Some("gif") => Ok(Format::Gif),
        Some(other) => Err(format!(
            "--render: unsupported file extension `.{other}` in {}: use .png (last frame) or .gif (animation)",
            path.display()
        )),
        None => Err(format!(
            "--render: {} has no file extension: use .png (last frame) or .gif (animation)",
            path.display()
        )),
    }
}

/// Parses `WxH` (e.g. `640x480`).
pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let bad = || format!("--size must be WxH in pixels, e.g. 640x480, got `{text}`");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    Ok((w, h))
}

/// The frame interval that plays the run in real time at `fps`: round(1 / (fps·dt)), ≥ 1.
pub fn real_time_every(fps: u32, dt: f32) -> u64 {
    (1.0 / (fps as f64 * dt as f64)).round().max(1.0) as u64
}

/// An animation in progress: the writer, the file, every how many steps a frame is drawn.
struct Gif {
    writer: GifWriter<BufWriter<File>>,
    every: u64,
}

/// A render in progress.
pub struct RenderJob {
    renderer: Renderer,
    path: PathBuf,
    /// Where the output is written until it is complete.
    staged: Staged,
    gif: Option<Gif>,
}

/// Checks the flags and opens the output.
pub fn start(
    flags: &RenderFlags,
    camera: Option<&jostle::scene::Camera>,
    dt: f32,
) -> Result<RenderJob, String> {
    let format = format_of(&flags.path)?;
    let (width, height) = parse_size(&flags.size)?;
    let settings = RenderSettings {
        width,
        height,
        camera: camera.map(Camera::from),
        contacts: flags.contacts,
    };
    let renderer = Renderer::new(settings).map_err(|e| format!("--render: {e}"))?;
    let staged = Staged::new(&flags.path);
    let gif = match format {
        Format::Png => None,
        Format::Gif => {
            if flags.frame_every == Some(0) {
                return Err("--frame-every must be at least 1".into());
            }
            let every = flags
                .frame_every
                .unwrap_or_else(|| real_time_every(flags.fps, dt));
            let file = File::create(staged.path())
                .map_err(|e| format!("{}: cannot create: {e}", flags.path.display()))?;
            let writer = GifWriter::new(BufWriter::new(file), flags.fps)
                .map_err(|e| format!("--fps: {e}"))?;
            Some(Gif { writer, every })
        }
    };
    Ok(RenderJob {
        renderer,
        path: flags.path.clone(),
        staged,
        gif,
    })
}

impl RenderJob {
    /// Records the world after `step` steps (0 = before the first).
    pub fn observe(&mut self, world: &World, step: u64) -> Result<(), String> {
        if let Some(gif) = &mut self.gif
            && step.is_multiple_of(gif.every)
        {
            let frame = self.renderer.render(world);
            gif.writer
                .push(frame)
                .map_err(|e| format!("{}: {e}", self.path.display()))?;
        }
        Ok(())
    }

    /// Writes the PNG of the final world, or ends the GIF, into the staged file; returns it,
    /// to be committed with the run's other outputs, and what was written.
    pub fn finish(mut self, world: &World) -> Result<(Staged, String), String> {
        let (w, h) = (
            self.renderer.settings().width,
            self.renderer.settings().height,
        );
        match self.gif {
            Some(Gif { writer, every }) => {
                let frames = writer.frames();
                let out = writer
                    .finish()
                    .map_err(|e| format!("{}: {e}", self.path.display()))?;
                // Flushed here, where a failure is reported (a drop would ignore it).
                out.into_inner()
                    .map_err(|e| format!("{}: {e}", self.path.display()))?;
                let message = format!(
                    "wrote {} ({frames} frames of {w}x{h}, every {every} steps)",
                    self.path.display()
                );
                Ok((self.staged, message))
            }
            None => {
                let image = self.renderer.render(world);
                image
                    .save_with_format(self.staged.path(), jostle_render::image::ImageFormat::Png)
                    .map_err(|e| format!("{}: {e}", self.path.display()))?;
                let message = format!("wrote {} ({w}x{h})", self.path.display());
                Ok((self.staged, message))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_formats_parse_or_explain() {
        assert_eq!(parse_size("640x480"), Ok((640, 480)));
        assert_eq!(parse_size("32X16"), Ok((32, 16)));
        for bad in ["640", "x480", "640x", "axb", "-1x2", ""] {
            assert!(parse_size(bad).unwrap_err().contains("--size"), "{bad}");
        }
        assert_eq!(format_of(Path::new("a/b.PNG")), Ok(Format::Png));
        assert_eq!(format_of(Path::new("b.gif")), Ok(Format::Gif));
        assert!(format_of(Path::new("b.jpg")).unwrap_err().contains(".jpg"));
        assert!(
            format_of(Path::new("b"))
                .unwrap_err()
                .contains("no file extension")
        );
    }

    #[test]
    fn real_time_interval() {
        assert_eq!(real_time_every(30, 1.0 / 60.0), 2);
        assert_eq!(real_time_every(60, 1.0 / 60.0), 1);
        assert_eq!(real_time_every(50, 1.0 / 60.0), 1);
        assert_eq!(real_time_every(10, 1.0 / 240.0), 24);
    }
}
