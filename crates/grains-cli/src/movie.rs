//! `grains movie RUN_DIR`: draws a run's frames into movie.gif (and
//! movie.mp4 when ffmpeg is on the PATH), walls in place at each frame.

use clap::Args;
use grains::render::{make_movie, ColorBy, MovieOptions, StillOptions, ViewAxis};
use grains::Error;
use std::path::PathBuf;

#[derive(Args)]
pub struct MovieArgs {
    /// The run's output directory (holding frames.pvd and frames/).
    run_dir: PathBuf,
    /// Frames per second (1 to 100).
    #[arg(long, default_value_t = 10)]
    fps: u32,
    /// Colour grains by: speed, height, id, kind or material (= kind).
    #[arg(long, default_value = "speed")]
    color: String,
    /// 3D runs: the axis the camera looks along (x, y or z).
    #[arg(long, default_value = "y")]
    view: String,
    /// Picture width in pixels.
    #[arg(long, default_value_t = 640)]
    width: u32,
    /// Write movie.gif only, even when ffmpeg is on the PATH.
    #[arg(long)]
    no_mp4: bool,
}

pub fn run(args: MovieArgs) -> grains::Result<()> {
    let color = ColorBy::parse(&args.color).ok_or_else(|| {
        Error::input(format!(
            "--color {}: unknown; allowed: {}",
            args.color,
            ColorBy::NAMES
        ))
    })?;
    let view = ViewAxis::parse(&args.view)
        .ok_or_else(|| Error::input(format!("--view {}: unknown; allowed: x, y, z", args.view)))?;
    if !(16..=8192).contains(&args.width) {
        return Err(Error::input(format!(
            "--width {}: must be between 16 and 8192 pixels",
            args.width
        )));
    }
    let opts = MovieOptions {
        fps: args.fps,
        still: StillOptions {
            width: args.width,
            color,
            view,
            max_speed: None,
        },
        mp4: !args.no_mp4,
    };
    let report = make_movie(&args.run_dir, &opts)?;
    println!(
        "grains: wrote {} ({} frames)",
        report.gif.display(),
        report.frames
    );
    if let Some(p) = report.mp4 {
        println!("grains: wrote {}", p.display());
    } else if let Some(note) = report.mp4_note {
        println!("grains: no mp4: {note}");
    }
    Ok(())
}
