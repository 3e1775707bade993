//! The free surface of a pile and its slope: the top of the highest grain in
//! each column (2D) or each square cell of the horizontal plane (3D), fitted
//! by least squares as height = a + b x. Used for the angle of repose (the
//! pile left after a side wall is removed) and the dynamic angle of a
//! rotating drum.

use crate::dim::Dim;
use crate::view::GrainView;
use std::collections::BTreeMap;

/// One fit: the surface points (x, top height) and the line through them.
#[derive(Clone, Debug, Default)]
pub struct SurfaceFit {
    pub points: Vec<[f64; 2]>,
    pub intercept: f64,
    pub slope: f64,
}

impl SurfaceFit {
    /// Angle of the fitted line with the horizontal, degrees, always ≥ 0.
    pub fn angle_deg(&self) -> f64 {
        self.slope.abs().atan().to_degrees()
    }
}

/// Least-squares line through `pts`; `None` with fewer than two distinct x.
pub fn fit_line(pts: &[[f64; 2]]) -> Option<(f64, f64)> {
    let n = pts.len() as f64;
    if pts.len() < 2 {
        return None;
    }
    let mx = pts.iter().map(|p| p[0]).sum::<f64>() / n;
    let my = pts.iter().map(|p| p[1]).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p[0] - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p[0] - mx) * (p[1] - my)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let b = sxy / sxx;
    Some((my - b * mx, b))
}

/// The surface of the mobile grains with x in `[x0, x1]`, in columns of
/// width `column` (m); columns whose top lies below `min_height` are left out.
pub fn surface<D: Dim>(
    view: &GrainView<D>,
    x0: f64,
    x1: f64,
    column: f64,
    min_height: f64,
) -> SurfaceFit {
    let p = &view.grains;
    let v = D::vertical();
    let mut top: BTreeMap<(i64, i64), (f64, f64)> = BTreeMap::new();
    for i in 0..p.len() {
        if p.frozen[i] {
            continue;
        }
        let x = D::get(p.pos[i], 0);
        if x < x0 || x > x1 {
            continue;
        }
        let h = D::get(p.pos[i], v) + p.radius[i];
        let ix = ((x - x0) / column).floor() as i64;
        let iy = if D::D == 3 {
            (D::get(p.pos[i], 1) / column).floor() as i64
        } else {
            0
        };
        let e = top.entry((ix, iy)).or_insert((x, f64::NEG_INFINITY));
        if h > e.1 {
            *e = (x0 + (ix as f64 + 0.5) * column, h);
        }
    }
    let points: Vec<[f64; 2]> = top
        .values()
        .filter(|(_, h)| *h >= min_height)
        .map(|&(x, h)| [x, h])
        .collect();
    let (intercept, slope) = fit_line(&points).unwrap_or((0.0, 0.0));
    SurfaceFit {
        points,
        intercept,
        slope,
    }
}

/// The same fit with only the points whose height is below `cap`.
pub fn refit_below(fit: SurfaceFit, cap: f64) -> SurfaceFit {
    let points: Vec<[f64; 2]> = fit.points.into_iter().filter(|p| p[1] < cap).collect();
    let (intercept, slope) = fit_line(&points).unwrap_or((0.0, 0.0));
    SurfaceFit {
        points,
        intercept,
        slope,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_a_line_exactly() {
        let pts: Vec<[f64; 2]> = (0..5).map(|k| [k as f64, 1.0 + 0.5 * k as f64]).collect();
        let (a, b) = fit_line(&pts).unwrap();
        assert!((a - 1.0).abs() < 1e-12 && (b - 0.5).abs() < 1e-12);
        assert!(fit_line(&pts[..1]).is_none());
    }

    #[test]
    fn refit_drops_the_plateau() {
        // A slope 0.5 below height 2 and a flat plateau at 3 (a wall column).
        let mut pts: Vec<[f64; 2]> = (0..4).map(|k| [k as f64, 2.0 - 0.5 * k as f64]).collect();
        pts.push([-1.0, 3.0]);
        let fit = refit_below(
            SurfaceFit {
                points: pts,
                ..Default::default()
            },
            2.5,
        );
        assert_eq!(fit.points.len(), 4);
        assert!((fit.slope + 0.5).abs() < 1e-12);
    }
}
