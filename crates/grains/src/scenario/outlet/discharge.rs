//! The discharge rate over the steady part of an outflow, and the files
//! outflow.csv and sensors.csv.
//!
//! Steadiness is judged on the running rate: the time from the first to
//! the last removal is cut into bins of equal width, each bin's rate is
//! its removed mass over the width, and the steady window is the longest
//! run of consecutive bins whose rates all lie within a tolerance of their
//! own median (so the start of the flow and a silo's slow emptying, which
//! may take most of the time, fall outside it). The rate is the least-squares slope of the cumulative
//! mass against time over the removals in that window, its error the
//! slope's standard error (the scatter of the grains' exits about the
//! line; it does not include the slow drift a silo's emptying can add).

use super::{class_of, Removal};
use crate::error::Result;
use crate::io::write_atomic;
use serde_json::{json, Map, Value};
use std::fmt::Write as _;
use std::path::Path;

/// One crossing of a sensor: time, +1 or −1, mass.
pub(crate) type Crossing = (f64, i8, f64);

/// Fewest removals and steady bins a rate is given for.
const MIN_REMOVALS: usize = 10;
const MIN_BINS: usize = 3;
/// Bins over the removals' span unless `outflow.bin` is given.
const DEFAULT_BINS: usize = 20;

/// The steady discharge, or why there is none.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SteadyRate {
    /// (rate kg/s, standard error kg/s, grains/s) when there is one.
    pub rate: Option<(f64, f64, f64)>,
    /// The window [t0, t1] (s).
    pub window: Option<(f64, f64)>,
    pub bin: f64,
    pub bins: usize,
    pub steady_bins: usize,
    pub median: f64,
    pub tolerance: f64,
    pub reason: &'static str,
}

impl SteadyRate {
    pub fn into_summary(self) -> Map<String, Value> {
        let mut m = Map::new();
        m.insert("discharge_rate".into(), json!(self.rate.map(|r| r.0)));
        m.insert("discharge_rate_error".into(), json!(self.rate.map(|r| r.1)));
        m.insert(
            "discharge_rate_grains".into(),
            json!(self.rate.map(|r| r.2)),
        );
        m.insert(
            "discharge_window".into(),
            json!(self.window.map(|w| [w.0, w.1])),
        );
        m.insert(
            "discharge_steadiness".into(),
            json!({
                "rule": "bins from the first to the last removal; the longest run of bins \
                         whose rates all lie within tolerance of their median; least-squares \
                         slope of the cumulative mass over that window",
                "bin_s": self.bin,
                "bins": self.bins,
                "steady_bins": self.steady_bins,
                "window_median_rate": self.median,
                "tolerance": self.tolerance,
                "note": self.reason,
            }),
        );
        m
    }
}

/// The steady discharge rate of `removed` (in time order).
pub(crate) fn steady_rate(removed: &[Removal], bin: Option<f64>, tolerance: f64) -> SteadyRate {
    let mut out = SteadyRate {
        rate: None,
        window: None,
        bin: 0.0,
        bins: 0,
        steady_bins: 0,
        median: 0.0,
        tolerance,
        reason: "",
    };
    if removed.len() < MIN_REMOVALS {
        out.reason = "fewer than 10 grains removed: no rate";
        return out;
    }
    let t0 = removed[0].time;
    let span = removed[removed.len() - 1].time - t0;
    let w = bin.unwrap_or(span / DEFAULT_BINS as f64);
    let nb = if w > 0.0 {
        (span / w).floor() as usize
    } else {
        0
    };
    out.bin = w;
    out.bins = nb;
    if nb < MIN_BINS {
        out.reason = "the removals span fewer than 3 bins: no rate";
        return out;
    }
    let mut mass = vec![0.0; nb];
    for r in removed {
        let b = ((r.time - t0) / w).floor() as usize;
        if b < nb {
            mass[b] += r.mass;
        }
    }
    let rates: Vec<f64> = mass.iter().map(|m| m / w).collect();
    // The longest run of bins within tolerance of its own median (the
    // earliest of equal ones); a few dozen bins, so every run is tried.
    let mut best = (0, 0, 0.0);
    for a in 0..nb {
        for b in (a + MIN_BINS..=nb).rev() {
            if b - a <= best.1 - best.0 {
                break;
            }
            let m = median(&rates[a..b]);
            if m > 0.0 && rates[a..b].iter().all(|r| (r - m).abs() <= tolerance * m) {
                best = (a, b, m);
                break;
            }
        }
    }
    out.median = best.2;
    out.steady_bins = best.1 - best.0;
    if out.steady_bins < MIN_BINS {
        out.reason = "fewer than 3 consecutive steady bins: no rate";
        return out;
    }
    let (a, b) = (t0 + best.0 as f64 * w, t0 + best.1 as f64 * w);
    out.window = Some((a, b));
    // Cumulative mass at each removal inside the window.
    let mut cum = 0.0;
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for r in removed {
        cum += r.mass;
        if r.time >= a && r.time < b {
            pts.push((r.time, cum));
        }
    }
    let Some((slope, se)) = fit_line(&pts) else {
        out.reason = "too few removals in the steady window: no rate";
        return out;
    };
    out.rate = Some((slope, se, pts.len() as f64 / (b - a)));
    out.reason = "steady window found";
    out
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

/// Least-squares slope of y on x and its standard error; `None` with
/// fewer than three points or no spread in x.
pub(crate) fn fit_line(pts: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = pts.len();
    if n < 3 {
        return None;
    }
    let nf = n as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / nf;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / nf;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    let ss: f64 = pts
        .iter()
        .map(|p| (p.1 - my - slope * (p.0 - mx)).powi(2))
        .sum();
    Some((slope, (ss / (nf - 2.0) / sxx).sqrt()))
}

/// outflow.csv: a row per step and outlet that removed grains: time,
/// step, outlet, count, mass, the cumulative count and mass over all
/// outlets, and the count in each size class.
pub(crate) fn write_outflow(
    dir: &Path,
    removed: &[Removal],
    names: &[&str],
    edges: &[f64],
) -> Result<()> {
    let classes = if edges.is_empty() { 0 } else { edges.len() + 1 };
    let mut csv = String::from("time,step,outlet,count,mass,cumulative_count,cumulative_mass");
    for k in 0..classes {
        let lo = if k == 0 { 0.0 } else { edges[k - 1] };
        match edges.get(k) {
            Some(hi) => write!(csv, ",d_{lo:e}_{hi:e}").unwrap(),
            None => write!(csv, ",d_{lo:e}_up").unwrap(),
        }
    }
    csv.push('\n');
    let (mut total_n, mut total_m) = (0u64, 0.0);
    let mut k = 0;
    while k < removed.len() {
        let (step, outlet) = (removed[k].step, removed[k].outlet);
        let end = k + removed[k..]
            .iter()
            .take_while(|r| r.step == step && r.outlet == outlet)
            .count();
        let group = &removed[k..end];
        let mass: f64 = group.iter().map(|r| r.mass).sum();
        total_n += group.len() as u64;
        for r in group {
            total_m += r.mass;
        }
        let _ = write!(
            csv,
            "{},{},{},{},{},{},{}",
            group[0].time,
            step,
            names[outlet as usize],
            group.len(),
            mass,
            total_n,
            total_m
        );
        let mut counts = vec![0u64; classes];
        for r in group {
            if classes > 0 {
                counts[class_of(edges, r.diameter)] += 1;
            }
        }
        for c in counts {
            let _ = write!(csv, ",{c}");
        }
        csv.push('\n');
        k = end;
    }
    write_atomic(&dir.join("outflow.csv"), csv.as_bytes())
}

/// sensors.csv: per sensor and time bin of width `bin` from 0 to `end`,
/// the crossings forward (along the normal) and back, the net count and
/// mass, the net mass rate and the cumulative net mass.
pub(crate) fn write_sensors(
    dir: &Path,
    sensors: &[(&str, &[Crossing])],
    bin: f64,
    end: f64,
) -> Result<()> {
    let mut csv =
        String::from("sensor,t0,t1,forward,back,net_count,net_mass,rate,cumulative_mass\n");
    let nb = if bin > 0.0 && end > 0.0 {
        ((end / bin).ceil() as usize).max(1)
    } else {
        1
    };
    for (name, crossings) in sensors {
        let mut rows = vec![(0u64, 0u64, 0.0f64); nb];
        for &(t, sign, m) in crossings.iter() {
            let b = if bin > 0.0 {
                ((t / bin).floor() as usize).min(nb - 1)
            } else {
                0
            };
            if sign > 0 {
                rows[b].0 += 1;
                rows[b].2 += m;
            } else {
                rows[b].1 += 1;
                rows[b].2 -= m;
            }
        }
        let mut cum = 0.0;
        for (b, (f, k, m)) in rows.into_iter().enumerate() {
            cum += m;
            let t0 = b as f64 * bin;
            let t1 = if b + 1 == nb { end } else { t0 + bin };
            let rate = if t1 > t0 { m / (t1 - t0) } else { 0.0 };
            let net = f as i64 - k as i64;
            let _ = writeln!(csv, "{name},{t0},{t1},{f},{k},{net},{m},{rate},{cum}");
        }
    }
    write_atomic(&dir.join("sensors.csv"), csv.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn removal(time: f64, mass: f64) -> Removal {
        Removal {
            step: (time * 1e4) as u64,
            time,
            outlet: 0,
            id: (time * 1e4) as u64,
            mass,
            diameter: 1e-3,
        }
    }

    /// A constant flow of 1 g every 10 ms for 2 s, then a trickle of 1 g
    /// every 0.1 s for 0.4 s: the rate is 0.1 kg/s exactly (every point on
    /// the line), the window inside the flow, the trickle outside it.
    #[test]
    fn steady_rate_of_a_constant_flow_is_its_slope() {
        let mut r: Vec<Removal> = (0..200).map(|k| removal(0.01 * k as f64, 1e-3)).collect();
        r.extend((0..4).map(|k| removal(2.1 + 0.1 * k as f64, 1e-3)));
        let s = steady_rate(&r, Some(0.1), 0.2);
        let (rate, err, grains) = s.rate.expect("a steady window");
        assert!((rate - 0.1).abs() < 1e-9, "{rate}");
        assert!(err < 1e-9, "{err}");
        assert!((grains - 100.0).abs() < 1e-6, "{grains}");
        let (a, b) = s.window.unwrap();
        // The 20 bins of the flow; the trickle's four are a tenth of it.
        assert!(a == 0.0 && (b - 2.0).abs() < 1e-9, "{a} {b}");
    }

    #[test]
    fn too_few_removals_give_no_rate() {
        let r: Vec<Removal> = (0..5).map(|k| removal(0.1 * k as f64, 1.0)).collect();
        assert_eq!(steady_rate(&r, None, 0.2).rate, None);
    }

    #[test]
    fn line_fit_error_of_a_known_scatter() {
        // By hand: x̄ = 1.5, ȳ = 3, Sxy = 8, Sxx = 5: slope 1.6;
        // residuals 0.4, -1.2, 1.2, -0.4, their squares sum to 3.2, so the
        // standard error is sqrt(3.2 / (4 - 2) / 5) = sqrt(0.32).
        let pts = [(0.0, 1.0), (1.0, 1.0), (2.0, 5.0), (3.0, 5.0)];
        let (slope, se) = fit_line(&pts).unwrap();
        assert!((slope - 1.6).abs() < 1e-12);
        assert!((se - 0.32f64.sqrt()).abs() < 1e-12, "{se}");
    }
}
