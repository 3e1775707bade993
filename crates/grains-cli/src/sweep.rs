//! `grains sweep`: runs a grid of variants of one scenario (each its own
//! output subdirectory), collects every summary.json scalar into sweep.csv
//! and plots one measurement against the first varied key.

use clap::Args;
use grains::measure::plot::{save_plot, Series, Titles, PALETTE};
use grains::runner::{self, RunOptions};
use grains::scenario;
use grains::scenario::sweep::{grid, variant_name, variant_sets};
use grains::Error;
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

#[derive(Args)]
pub struct SweepArgs {
    /// Scenario file (TOML).
    scenario: PathBuf,
    /// A key and its values, e.g. --vary walls.0.motion.frequency=40,60,80 (repeatable; the grid is their product). KEY1+KEY2=... gives several keys the same value.
    #[arg(long = "vary", value_name = "KEY=V1,V2,...", required = true)]
    vary: Vec<String>,
    /// Fixed overrides applied to every variant (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// Variants run at the same time (at most one per CPU this process may use).
    #[arg(long, default_value_t = 1)]
    jobs: usize,
    /// Worker threads of each variant [default: the CPUs this process may use, shared among the jobs].
    #[arg(long)]
    threads: Option<usize>,
    /// Output directory [default: runs/<scenario name>-sweep].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace the runs of an earlier sweep in the output directory (without
    /// it, a variant's directory that holds a run is refused).
    #[arg(long)]
    overwrite: bool,
    /// Run this many steps per variant instead of the scenario's length.
    #[arg(long)]
    steps: Option<u64>,
    /// summary.json scalar to plot against the first varied key (a varied `seed` is averaged over, with error bars).
    #[arg(long)]
    plot: Option<String>,
    /// Seconds between two progress lines of a running variant (each names its variant; 0: at every report, every 256 steps).
    #[arg(long, value_name = "SECONDS", default_value_t = 10.0)]
    progress_every: f64,
}

/// The CPUs this process may use (its affinity mask and cgroup quota, as
/// the standard library reads them), at least one.
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The jobs run at once and the threads of each, so that together they ask
/// for no more than `cores` threads: at most one job per core, and each
/// job's threads (asked for, or by default an equal share of the cores)
/// cut to its share. Says so on stderr when it cuts what was asked for.
fn share_cores(jobs: usize, threads: Option<usize>, cores: usize) -> (usize, usize) {
    let jobs_run = jobs.clamp(1, cores);
    if jobs_run < jobs {
        eprintln!("grains: --jobs {jobs} on {cores} CPUs: running {jobs_run} variants at a time");
    }
    let share = (cores / jobs_run).max(1);
    let threads_run = threads.unwrap_or(share).min(share);
    if let Some(t) = threads.filter(|&t| t > threads_run) {
        eprintln!(
            "grains: --threads {t} × {jobs_run} jobs on {cores} CPUs: {threads_run} thread(s) per variant"
        );
    }
    (jobs_run, threads_run)
}

/// Parses `KEY=V1,V2,...`.
fn parse_vary(s: &str) -> grains::Result<(String, Vec<String>)> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| Error::input(format!("--vary {s}: expected KEY=V1,V2,...")))?;
    let vals: Vec<String> = v
        .split(',')
        .map(|x| x.trim().to_string())
        .filter(|x| !x.is_empty())
        .collect();
    if k.split('+').any(|k| k.trim().is_empty()) || vals.is_empty() {
        return Err(Error::input(format!(
            "--vary {s}: expected KEY=V1,V2,... with at least one value"
        )));
    }
    Ok((k.trim().to_string(), vals))
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

pub fn run(args: SweepArgs) -> grains::Result<()> {
    let axes = args
        .vary
        .iter()
        .map(|s| parse_vary(s))
        .collect::<grains::Result<Vec<_>>>()?;
    if args.jobs == 0 {
        return Err(Error::input("--jobs must be at least 1"));
    }
    if args.steps == Some(0) {
        return Err(Error::input("--steps must be at least 1"));
    }
    if args.threads == Some(0) {
        return Err(Error::input("--threads must be at least 1"));
    }
    let every = args.progress_every;
    if !(every.is_finite() && every >= 0.0) {
        return Err(Error::input(format!(
            "--progress-every {every}: must be a number of seconds >= 0"
        )));
    }
    let every = std::time::Duration::from_secs_f64(every);
    // Load every variant first: a bad key or value fails before any run.
    let variants = grid(&axes);
    let mut loaded = Vec::new();
    for vals in &variants {
        let sets = variant_sets(&args.sets, &axes, vals);
        loaded.push(scenario::load_file(&args.scenario, &sets)?);
    }
    let name = loaded[0].scenario.name.clone();
    let out = args
        .out
        .unwrap_or_else(|| Path::new("runs").join(format!("{name}-sweep")));
    runner::prepare(&out)?;
    let dirs: Vec<PathBuf> = variants
        .iter()
        .map(|v| out.join(variant_name(&axes, v)))
        .collect();
    grains::run_dir::claim_all(&dirs, args.overwrite)?;
    let (jobs, threads) = share_cores(args.jobs.min(variants.len()), args.threads, cores());
    eprintln!(
        "grains: sweep of {} variants of {} with {} jobs of {} thread(s) -> {}",
        variants.len(),
        args.scenario.display(),
        jobs,
        threads,
        out.display()
    );
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<grains::Result<Value>>>> =
        Mutex::new((0..variants.len()).map(|_| None).collect());
    // Each job its own pool, so that the jobs never ask for more threads
    // than the cores they share.
    let pools = (0..jobs)
        .map(|_| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| Error::input(format!("--threads {threads}: {e}")))
        })
        .collect::<grains::Result<Vec<_>>>()?;
    std::thread::scope(|s| {
        for pool in &pools {
            s.spawn(|| {
                pool.install(|| loop {
                    let k = next.fetch_add(1, Ordering::SeqCst);
                    if k >= variants.len() {
                        break;
                    }
                    let dir = out.join(variant_name(&axes, &variants[k]));
                    let opts = RunOptions {
                        out_dir: dir,
                        steps: args.steps,
                        overwrite: args.overwrite,
                        ..RunOptions::default()
                    };
                    let name = variant_name(&axes, &variants[k]);
                    let mut progress = crate::progress::for_variant(&name, every);
                    let r = runner::run(&loaded[k], &opts, progress.as_mut());
                    match &r {
                        Ok(_) => eprintln!("grains: done {}", variant_name(&axes, &variants[k])),
                        Err(e) => eprintln!(
                            "grains: variant {} failed: {e}",
                            variant_name(&axes, &variants[k])
                        ),
                    }
                    results.lock().expect("no panics while locked")[k] = Some(r);
                })
            });
        }
    });
    let results = results.into_inner().expect("no panics while locked");

    // sweep.csv: varied keys, status, then every numeric scalar.
    let mut keys = BTreeSet::new();
    for v in results.iter().flatten().flatten() {
        if let Value::Object(m) = v {
            keys.extend(
                m.iter()
                    .filter(|(_, x)| x.is_number())
                    .map(|(k, _)| k.clone()),
            );
        }
    }
    let mut csv = axes
        .iter()
        .map(|(k, _)| csv_field(k))
        .chain(["status".to_string()])
        .chain(keys.iter().map(|k| csv_field(k)))
        .collect::<Vec<_>>()
        .join(",");
    csv.push('\n');
    let mut failed = 0;
    for (vals, r) in variants.iter().zip(&results) {
        let mut row: Vec<String> = vals.iter().map(|v| csv_field(v)).collect();
        match r {
            Some(Ok(v)) => {
                row.push("ok".into());
                for k in &keys {
                    row.push(v.get(k).map(|x| x.to_string()).unwrap_or_default());
                }
            }
            Some(Err(e)) => {
                failed += 1;
                row.push(csv_field(&format!("error: {e}")));
                row.extend(keys.iter().map(|_| String::new()));
            }
            None => unreachable!("every variant ran"),
        }
        csv.push_str(&row.join(","));
        csv.push('\n');
    }
    grains::io::write_atomic(&out.join("sweep.csv"), csv.as_bytes())?;
    print!("{csv}");

    if let Some(m) = &args.plot {
        plot_against_first_key(&out, m, &axes, &variants, &results, &keys)?;
    }
    if failed > 0 {
        return Err(Error::input(format!(
            "{failed} of {} variants failed (see sweep.csv)",
            variants.len()
        )));
    }
    Ok(())
}

/// The values of the measurement at one x (one per seed).
type Samples = (f64, Vec<f64>);

/// Plots measurement `m` against the first varied key: one line per
/// combination of the other keys. A varied `seed` is averaged over instead:
/// the line is the mean over seeds with standard-error bars, and the means
/// go to `sweep_mean.csv` (granular measurements from one seed are noisy).
fn plot_against_first_key(
    out: &Path,
    m: &str,
    axes: &[(String, Vec<String>)],
    variants: &[Vec<String>],
    results: &[Option<grains::Result<Value>>],
    keys: &BTreeSet<String>,
) -> grains::Result<()> {
    let seed_axis = axes
        .iter()
        .skip(1)
        .position(|a| a.0 == "seed")
        .map(|i| i + 1);
    let mut groups: Vec<(Vec<String>, Vec<Samples>)> = Vec::new();
    for (vals, r) in variants.iter().zip(results) {
        let Some(Ok(v)) = r else { continue };
        let x: f64 = vals[0].parse().map_err(|_| {
            Error::input(format!(
                "--plot needs numeric values of {}, got {}",
                axes[0].0, vals[0]
            ))
        })?;
        let Some(y) = v.get(m).and_then(Value::as_f64) else {
            return Err(Error::input(format!(
                "--plot {m}: not a number in summary.json (have: {})",
                keys.iter().cloned().collect::<Vec<_>>().join(", ")
            )));
        };
        let rest: Vec<String> = (1..vals.len())
            .filter(|&k| Some(k) != seed_axis)
            .map(|k| vals[k].clone())
            .collect();
        let g = match groups.iter().position(|g| g.0 == rest) {
            Some(i) => &mut groups[i].1,
            None => {
                groups.push((rest, Vec::new()));
                &mut groups.last_mut().expect("just pushed").1
            }
        };
        match g.iter_mut().find(|(gx, _)| *gx == x) {
            Some((_, ys)) => ys.push(y),
            None => g.push((x, vec![y])),
        }
    }
    let mut means = String::new();
    let mut series = Vec::new();
    for (i, (rest, mut pts)) in groups.into_iter().enumerate() {
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let stats: Vec<(f64, f64, f64, usize)> = pts
            .iter()
            .map(|(x, ys)| {
                let (mean, err) = mean_and_standard_error(ys);
                (*x, mean, err, ys.len())
            })
            .collect();
        for (x, mean, err, n) in &stats {
            let mut row = rest.iter().map(|s| csv_field(s)).collect::<Vec<_>>();
            row.extend([
                x.to_string(),
                mean.to_string(),
                err.to_string(),
                n.to_string(),
            ]);
            means.push_str(&row.join(","));
            means.push('\n');
        }
        series.push(Series {
            points: stats.iter().map(|s| [s.0, s.1]).collect(),
            colour: PALETTE[i % PALETTE.len()],
            lines: true,
            errors: seed_axis.map(|_| stats.iter().map(|s| s.2).collect()),
        });
    }
    if seed_axis.is_some() {
        let mut header: Vec<String> = axes
            .iter()
            .skip(1)
            .filter(|a| a.0 != "seed")
            .map(|a| csv_field(&a.0))
            .collect();
        header.extend([
            csv_field(&axes[0].0),
            format!("{m}_mean"),
            format!("{m}_stderr"),
            "seeds".into(),
        ]);
        let csv = format!("{}\n{means}", header.join(","));
        grains::io::write_atomic(&out.join("sweep_mean.csv"), csv.as_bytes())?;
    }
    let path = out.join(format!("sweep_{m}.png"));
    let y = if seed_axis.is_some() {
        format!("{m} (mean over seeds)")
    } else {
        m.to_string()
    };
    let titles = Titles {
        x: &axes[0].0,
        y: &y,
    };
    save_plot(&path, &series, true, titles)?;
    eprintln!(
        "grains: plotted {m}{} against {} -> {}",
        if seed_axis.is_some() {
            " (mean over seeds, standard-error bars)"
        } else {
            ""
        },
        axes[0].0,
        path.display()
    );
    Ok(())
}

/// Mean and standard error of the mean (0 for a single sample).
fn mean_and_standard_error(ys: &[f64]) -> (f64, f64) {
    let n = ys.len() as f64;
    let mean = ys.iter().sum::<f64>() / n;
    if ys.len() < 2 {
        return (mean, 0.0);
    }
    let var = ys.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Jobs × threads never exceed the cores; the default shares them out.
    #[test]
    fn jobs_and_threads_share_the_cores() {
        assert_eq!(share_cores(1, None, 8), (1, 8));
        assert_eq!(share_cores(4, None, 8), (4, 2));
        assert_eq!(share_cores(3, None, 8), (3, 2));
        assert_eq!(share_cores(4, Some(1), 8), (4, 1));
        assert_eq!(share_cores(4, Some(4), 8), (4, 2));
        assert_eq!(share_cores(16, None, 8), (8, 1));
        assert_eq!(share_cores(2, Some(2), 2), (2, 1));
        for jobs in 1..20 {
            for cores in 1..20 {
                for threads in [None, Some(1), Some(3), Some(64)] {
                    let (j, t) = share_cores(jobs, threads, cores);
                    assert!(
                        j >= 1 && t >= 1 && j * t <= cores,
                        "{jobs} {threads:?} {cores}"
                    );
                }
            }
        }
    }

    #[test]
    fn vary_arguments_parse() {
        assert!(parse_vary("k=").is_err());
        assert_eq!(parse_vary("k=1, 2").unwrap().1, vec!["1", "2"]);
        assert!(parse_vary("a+=1").is_err());
    }

    #[test]
    fn standard_error_of_the_mean() {
        let (m, e) = mean_and_standard_error(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(m, 2.5);
        // sample variance 5/3, over n = 4
        assert!((e - (5.0f64 / 12.0).sqrt()).abs() < 1e-15);
        assert_eq!(mean_and_standard_error(&[7.0]), (7.0, 0.0));
    }
}
