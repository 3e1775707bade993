//! Draws a speed-up curve like the seeds' Figs. 1–2: speed-up
//! S(p) = t(1)/t(p) versus ranks p, measured points joined by lines, and
//! the ideal S = p as a grey line.
//!
//! `cargo run --release --example plot_scaling -- scaling.csv out.png`
//! where scaling.csv is what `bench/mpi_scaling.sh` writes (header, then
//! `ranks,wall_seconds,...` rows, one of them for one rank).

use grains::measure::plot::{save_plot, Series, Titles, PALETTE};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 3 {
        return Err("usage: plot_scaling SCALING.csv OUT.png".into());
    }
    let text = std::fs::read_to_string(&args[1]).map_err(|e| format!("{}: {e}", args[1]))?;
    let mut rows = Vec::new();
    for (k, line) in text.lines().enumerate().skip(1) {
        let mut f = line.split(',');
        let bad = || format!("{}: line {}: want ranks,wall_seconds,...", args[1], k + 1);
        let p: f64 = f.next().and_then(|x| x.parse().ok()).ok_or_else(bad)?;
        let t: f64 = f.next().and_then(|x| x.parse().ok()).ok_or_else(bad)?;
        rows.push((p, t));
    }
    let t1 = rows
        .iter()
        .find(|r| r.0 == 1.0)
        .map(|r| r.1)
        .ok_or_else(|| format!("{}: no row for one rank", args[1]))?;
    let pmax = rows.iter().map(|r| r.0).fold(1.0, f64::max);
    let measured = Series {
        points: rows.iter().map(|&(p, t)| [p, t1 / t]).collect(),
        colour: PALETTE[0],
        lines: true,
        errors: None,
    };
    let ideal = Series {
        points: vec![[1.0, 1.0], [pmax, pmax]],
        colour: PALETTE[5],
        lines: true,
        errors: None,
    };
    let titles = Titles {
        x: "ranks p",
        y: "speed-up t(1)/t(p)",
    };
    save_plot(Path::new(&args[2]), &[ideal, measured], false, titles)?;
    println!("{}", args[2]);
    Ok(())
}
