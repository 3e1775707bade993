//! Movies of a run: every frame of `frames.pvd` drawn by one [`Painter`]
//! with its walls at its time, encoded as `movie.gif` (the `gif` crate,
//! pure Rust) and, when `ffmpeg` is on the PATH, `movie.mp4` too.

use super::scene::Scene;
use super::still::{Painter, StillOptions};
use crate::error::{Error, Result};
use crate::io::{read_frame, read_series, Frame, FrameEntry, Image};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

/// Choices for a movie.
#[derive(Clone, Debug, PartialEq)]
pub struct MovieOptions {
    pub fps: u32,
    pub still: StillOptions,
    /// Also write movie.mp4 when ffmpeg is found.
    pub mp4: bool,
}

impl Default for MovieOptions {
    fn default() -> Self {
        MovieOptions {
            fps: 10,
            still: StillOptions {
                width: 640,
                ..Default::default()
            },
            mp4: true,
        }
    }
}

/// What [`make_movie`] wrote.
#[derive(Clone, Debug)]
pub struct MovieReport {
    pub frames: usize,
    pub gif: PathBuf,
    pub mp4: Option<PathBuf>,
    /// Why no mp4 was written, when one was asked for.
    pub mp4_note: Option<String>,
}

/// Reads frame `e` and gives it the run's box (VTK frames carry none).
pub fn load_frame(e: &FrameEntry, scene: &Scene) -> Result<Frame> {
    let mut f = read_frame(&e.path)?;
    scene.apply(&mut f);
    Ok(f)
}

/// The run's scene, or a bare one from the box of `frame` when the run
/// directory has no scene.json (runs from before it existed).
pub fn scene_or_bare(run_dir: &Path, frame: &mut Frame) -> Result<Scene> {
    Ok(match Scene::read(run_dir)? {
        Some(s) => {
            s.apply(frame);
            s
        }
        None => Scene::bare(frame),
    })
}

/// A painter for the series: its rectangle and colour scale from the first,
/// middle and last frames.
pub fn series_painter(
    entries: &[FrameEntry],
    scene: &Scene,
    first: &Frame,
    opts: &StillOptions,
) -> Result<Painter> {
    let n = entries.len();
    let mut sample = Vec::new();
    for k in [n / 2, n - 1] {
        if k > 0 {
            sample.push(load_frame(&entries[k], scene)?);
        }
    }
    let mut refs: Vec<&Frame> = vec![first];
    refs.extend(sample.iter());
    Ok(Painter::new(&refs, opts))
}

/// Draws every frame of `run_dir` into `run_dir/movie.gif` (and movie.mp4).
pub fn make_movie(run_dir: &Path, opts: &MovieOptions) -> Result<MovieReport> {
    if opts.fps == 0 || opts.fps > 100 {
        return Err(Error::input(format!(
            "--fps {}: must be between 1 and 100 (GIF delays are in hundredths of a second)",
            opts.fps
        )));
    }
    let entries = read_series(run_dir)?;
    if entries.is_empty() {
        return Err(Error::input(format!(
            "{}: frames.pvd lists no frames",
            run_dir.display()
        )));
    }
    let mut first = read_frame(&entries[0].path)?;
    let scene = scene_or_bare(run_dir, &mut first)?;
    let painter = series_painter(&entries, &scene, &first, &opts.still)?;
    let (w, h) = (painter.width, painter.height());
    if w > u16::MAX as u32 || h > u16::MAX as u32 {
        return Err(Error::input(format!(
            "a movie of {w} x {h} pixels is larger than GIF allows (65535)"
        )));
    }
    let gif_path = run_dir.join("movie.gif");
    let tmp = run_dir.join(".movie.gif.partial");
    let file = std::fs::File::create(&tmp).map_err(|e| Error::io(&tmp, e))?;
    let gif_err = |e: gif::EncodingError| Error::io(&tmp, std::io::Error::other(e));
    let mut gif = GifWriter::new(std::io::BufWriter::new(file), w, h, opts.fps).map_err(gif_err)?;
    let (mut ffmpeg, mut mp4_note) = match opts.mp4 {
        true => match start_ffmpeg(run_dir, w, h, opts.fps) {
            Ok(child) => (Some(child), None),
            Err(note) => (None, Some(note)),
        },
        false => (None, None),
    };
    for (k, e) in entries.iter().enumerate() {
        let frame = if k == 0 {
            first.clone()
        } else {
            load_frame(e, &scene)?
        };
        let img = painter.paint(&frame, &scene.wires(frame.time));
        gif.push(&img).map_err(gif_err)?;
        if let Some(child) = ffmpeg.as_mut() {
            if let Err(note) = feed(child, &img) {
                mp4_note = Some(note);
                let _ = child.kill();
                ffmpeg = None;
            }
        }
    }
    let inner = gif.finish().map_err(|e| Error::io(&tmp, e))?;
    inner
        .into_inner()
        .map_err(|e| Error::io(&tmp, e.into_error()))?
        .sync_all()
        .map_err(|e| Error::io(&tmp, e))?;
    std::fs::rename(&tmp, &gif_path).map_err(|e| Error::io(&gif_path, e))?;
    let mp4 = match ffmpeg {
        Some(child) => match finish_ffmpeg(child) {
            Ok(()) => Some(run_dir.join("movie.mp4")),
            Err(note) => {
                mp4_note = Some(note);
                None
            }
        },
        None => None,
    };
    Ok(MovieReport {
        frames: entries.len(),
        gif: gif_path,
        mp4,
        mp4_note,
    })
}

/// An animated GIF being written: frames of one size, one fixed palette,
/// looping forever.
pub struct GifWriter<W: std::io::Write> {
    enc: gif::Encoder<W>,
    size: (u16, u16),
    delay: u16,
    indices: Vec<u8>,
}

impl<W: std::io::Write> GifWriter<W> {
    /// A GIF of `w` × `h` pixels (each at most 65535) at `fps` (1 to 100).
    pub fn new(out: W, w: u32, h: u32, fps: u32) -> std::result::Result<Self, gif::EncodingError> {
        let size = (w as u16, h as u16);
        let mut enc = gif::Encoder::new(out, size.0, size.1, &PALETTE.rgb)?;
        enc.set_repeat(gif::Repeat::Infinite)?;
        Ok(GifWriter {
            enc,
            size,
            delay: (100 / fps.clamp(1, 100)) as u16,
            indices: vec![0; w as usize * h as usize],
        })
    }

    /// Appends `img` (of the GIF's size).
    pub fn push(&mut self, img: &Image) -> std::result::Result<(), gif::EncodingError> {
        PALETTE.index(&img.rgb, &mut self.indices);
        let mut f =
            gif::Frame::from_indexed_pixels(self.size.0, self.size.1, &self.indices[..], None);
        f.delay = self.delay;
        self.enc.write_frame(&f)
    }

    /// Ends the GIF; gives back the writer.
    pub fn finish(self) -> std::io::Result<W> {
        self.enc.into_inner()
    }
}

/// Whether a program called `name` is on the PATH.
fn on_path(name: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|d| {
            let p = d.join(name);
            p.is_file()
        })
    })
}

fn start_ffmpeg(dir: &Path, w: u32, h: u32, fps: u32) -> std::result::Result<Child, String> {
    if !on_path("ffmpeg") {
        return Err("ffmpeg is not on the PATH: movie.gif only".into());
    }
    Command::new("ffmpeg")
        .args([
            "-loglevel",
            "error",
            "-y",
            "-f",
            "rawvideo",
            "-pix_fmt",
            "rgb24",
        ])
        .args(["-s", &format!("{w}x{h}"), "-r", &fps.to_string(), "-i", "-"])
        // H.264 in yuv420p needs even sides.
        .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white"])
        .args(["-pix_fmt", "yuv420p"])
        // A few times faster than the default preset, for a file not much
        // larger: the movie should not cost more than the run.
        .args(["-preset", "veryfast"])
        .arg(dir.join("movie.mp4"))
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("ffmpeg did not start: {e}"))
}

fn feed(child: &mut Child, img: &Image) -> std::result::Result<(), String> {
    let stdin = child.stdin.as_mut().ok_or("ffmpeg has no input")?;
    stdin
        .write_all(&img.rgb)
        .map_err(|e| format!("ffmpeg stopped reading frames: {e}"))
}

fn finish_ffmpeg(mut child: Child) -> std::result::Result<(), String> {
    drop(child.stdin.take());
    let out = child
        .wait_with_output()
        .map_err(|e| format!("ffmpeg: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "ffmpeg failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    }
}

/// A fixed palette (6 × 7 × 6 colour cube and 4 extra greys): every frame
/// uses the same one, so no per-frame quantizer runs.
struct Palette {
    rgb: [u8; 768],
}

const LEVELS: [u32; 3] = [6, 7, 6];

const PALETTE: Palette = Palette::new();

impl Palette {
    const fn new() -> Self {
        let mut rgb = [0u8; 768];
        let mut i = 0;
        while i < 252 {
            let (r, g, b) = (i / 42, (i / 6) % 7, i % 6);
            rgb[3 * i] = (r * 255 / 5) as u8;
            rgb[3 * i + 1] = (g * 255 / 6) as u8;
            rgb[3 * i + 2] = (b * 255 / 5) as u8;
            i += 1;
        }
        let greys = [40u8, 90, 150, 210];
        let mut k = 0;
        while k < 4 {
            rgb[3 * (252 + k)] = greys[k];
            rgb[3 * (252 + k) + 1] = greys[k];
            rgb[3 * (252 + k) + 2] = greys[k];
            k += 1;
        }
        Palette { rgb }
    }

    /// The nearest cube colour of each RGB pixel (greys may take an extra grey).
    fn index(&self, rgb: &[u8], out: &mut [u8]) {
        let level = |c: u8, n: u32| (c as u32 * (n - 1) + 127) / 255;
        for (px, o) in rgb.chunks_exact(3).zip(out.iter_mut()) {
            let (r, g, b) = (
                level(px[0], LEVELS[0]),
                level(px[1], LEVELS[1]),
                level(px[2], LEVELS[2]),
            );
            let mut idx = (r * 42 + g * 6 + b) as u8;
            if px[0] == px[1] && px[1] == px[2] {
                let c = px[0] as i32;
                let cube = self.rgb[3 * idx as usize] as i32;
                let mut best = (c - cube).abs();
                for k in 252..256 {
                    let d = (c - self.rgb[3 * k] as i32).abs();
                    if d < best {
                        best = d;
                        idx = k as u8;
                    }
                }
            }
            *o = idx;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::atomic::tests::scratch_dir;
    use crate::io::frame::tests::sample_2d;
    use crate::io::VtkSeries;

    #[test]
    fn palette_keeps_white_black_and_nearby_colours() {
        let mut out = [0u8; 4];
        PALETTE.index(
            &[255, 255, 255, 0, 0, 0, 40, 40, 40, 253, 231, 37],
            &mut out,
        );
        let colour = |i: u8| &PALETTE.rgb[3 * i as usize..3 * i as usize + 3];
        assert_eq!(colour(out[0]), [255, 255, 255]);
        assert_eq!(colour(out[1]), [0, 0, 0]);
        assert_eq!(colour(out[2]), [40, 40, 40]);
        // Viridis' yellow within half a cube step per channel.
        let y = colour(out[3]);
        for (a, b) in y.iter().zip([253u8, 231, 37]) {
            assert!((*a as i32 - b as i32).abs() <= 26, "{y:?}");
        }
    }

    #[test]
    fn a_movie_has_one_gif_frame_per_vtk_frame() {
        let dir = scratch_dir("movie");
        let mut series = VtkSeries::new(&dir).unwrap();
        let mut f = sample_2d();
        for k in 0..3 {
            f.time = 0.1 * k as f64;
            f.step = k;
            f.pos[0][0] = 1.0 + k as f64;
            series.write(&f).unwrap();
        }
        Scene::bare(&f).write(&dir).unwrap();
        let opts = MovieOptions {
            mp4: false,
            ..Default::default()
        };
        let report = make_movie(&dir, &opts).unwrap();
        assert_eq!(report.frames, 3);
        let mut dec = gif::DecodeOptions::new()
            .read_info(std::fs::File::open(&report.gif).unwrap())
            .unwrap();
        let mut n = 0;
        while let Some(fr) = dec.read_next_frame().unwrap() {
            assert_eq!(fr.delay, 10);
            n += 1;
        }
        assert_eq!(n, 3);
        assert_eq!(dec.width(), 640);
        // A truncated frame stops the movie with the file's name.
        let last = dir.join("frames/frame_000002.vtp");
        let text = std::fs::read_to_string(&last).unwrap();
        std::fs::write(&last, &text[..100]).unwrap();
        let err = make_movie(&dir, &opts).unwrap_err().to_string();
        assert!(
            err.contains("frame_000002.vtp") && err.contains("truncated"),
            "{err}"
        );
        let bad = MovieOptions { fps: 0, ..opts };
        assert!(make_movie(&dir, &bad)
            .unwrap_err()
            .to_string()
            .contains("--fps"));
    }
}
