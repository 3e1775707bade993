//! Reads back the VTK frames this crate writes (`frames.pvd`, `.vtp`, and
//! `.pvtp` with its pieces) into [`Frame`]s, for movies and the viewer.
//!
//! Only the layout of [`super::vtk`] is understood (ASCII data arrays with
//! the names it writes); that is all a run directory holds. A file that is
//! missing, cut short (a run killed while writing) or not of that layout is
//! an error naming the file, never a panic.

use super::frame::Frame;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// One entry of a run's `frames.pvd`: the frame's time and its file.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameEntry {
    pub time: f64,
    pub path: PathBuf,
}

/// The frames listed in `run_dir/frames.pvd`, in the order written.
pub fn read_series(run_dir: &Path) -> Result<Vec<FrameEntry>> {
    read_collection(
        run_dir,
        "frames.pvd",
        "the run wrote no frames (output.frames = false?)",
    )
}

/// The entries of the collection `run_dir/name` (a `.pvd`), in the order
/// written; `missing` says why it may be absent.
pub fn read_collection(run_dir: &Path, name: &str, missing: &str) -> Result<Vec<FrameEntry>> {
    let pvd = run_dir.join(name);
    let text = std::fs::read_to_string(&pvd).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => {
            Error::input(format!("{}: not found; {missing}", pvd.display()))
        }
        _ => Error::io(&pvd, e),
    })?;
    if !text.contains("</VTKFile>") {
        return Err(Error::input(format!(
            "{}: truncated (no closing </VTKFile>)",
            pvd.display()
        )));
    }
    let mut out = Vec::new();
    for tag in text.split("<DataSet").skip(1) {
        let time = attr(tag, "timestep")
            .and_then(|s| s.parse::<f64>().ok())
            .ok_or_else(|| bad(&pvd, "a DataSet without a numeric timestep"))?;
        let file = attr(tag, "file").ok_or_else(|| bad(&pvd, "a DataSet without a file"))?;
        out.push(FrameEntry {
            time,
            path: run_dir.join(unescape(file)),
        });
    }
    Ok(out)
}

/// Reads one frame file: a `.vtp`, or a `.pvtp` whose pieces are joined in
/// rank order.
pub fn read_frame(path: &Path) -> Result<Frame> {
    let text = read_text(path)?;
    if text.contains("<PPolyData") {
        let dir = path.parent().unwrap_or(Path::new("."));
        let mut whole: Option<Frame> = None;
        for tag in text.split("<Piece").skip(1) {
            let src = attr(tag, "Source").ok_or_else(|| bad(path, "a Piece without a Source"))?;
            let piece = parse_vtp(&dir.join(unescape(src)))?;
            whole = Some(match whole {
                None => piece,
                Some(mut w) => {
                    w.id.extend(piece.id);
                    w.kind.extend(piece.kind);
                    w.pos.extend(piece.pos);
                    w.vel.extend(piece.vel);
                    w.omega.extend(piece.omega);
                    w.radius.extend(piece.radius);
                    w.mass.extend(piece.mass);
                    w
                }
            });
        }
        return whole.ok_or_else(|| bad(path, "no pieces listed"));
    }
    parse_text(path, &text)
}

fn parse_vtp(path: &Path) -> Result<Frame> {
    parse_text(path, &read_text(path)?)
}

fn read_text(path: &Path) -> Result<String> {
    let text = std::fs::read_to_string(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => Error::input(format!(
            "{}: frame file not found (listed in frames.pvd; was the run directory changed?)",
            path.display()
        )),
        _ => Error::io(path, e),
    })?;
    if !text.trim_end().ends_with("</VTKFile>") {
        return Err(Error::input(format!(
            "{}: truncated frame file ({} bytes, no closing </VTKFile>; was the run killed \
             while writing it?)",
            path.display(),
            text.len()
        )));
    }
    Ok(text)
}

fn bad(path: &Path, what: &str) -> Error {
    Error::input(format!(
        "{}: not a grains VTK frame: {what}",
        path.display()
    ))
}

/// The value of `name="…"` in the start of `tag`.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let end = tag.find('>').unwrap_or(tag.len());
    let head = &tag[..end];
    let key = format!(" {name}=\"");
    let start = head.find(&key)? + key.len();
    let len = head[start..].find('"')?;
    Some(&head[start..start + len])
}

fn unescape(s: &str) -> String {
    s.replace("&quot;", "\"")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&")
}

/// The numbers of the `DataArray` called `name`, checked to hold `want`.
fn data_array(path: &Path, text: &str, name: &str, want: usize) -> Result<Vec<f64>> {
    let key = format!("Name=\"{name}\"");
    let at = text
        .find(&key)
        .ok_or_else(|| bad(path, &format!("no data array '{name}'")))?;
    let body_start = at + text[at..].find('>').ok_or_else(|| bad(path, name))? + 1;
    let body_len = text[body_start..]
        .find("</DataArray>")
        .ok_or_else(|| bad(path, &format!("data array '{name}' is not closed")))?;
    let mut out = Vec::with_capacity(want);
    for tok in text[body_start..body_start + body_len].split_ascii_whitespace() {
        let v = tok.parse::<f64>().map_err(|_| {
            bad(
                path,
                &format!("data array '{name}' holds '{tok}', not a number"),
            )
        })?;
        out.push(v);
    }
    if out.len() != want {
        return Err(bad(
            path,
            &format!(
                "data array '{name}' has {} values, {want} expected",
                out.len()
            ),
        ));
    }
    Ok(out)
}

fn parse_text(path: &Path, text: &str) -> Result<Frame> {
    let n = text
        .split("<Piece")
        .nth(1)
        .and_then(|t| attr(t, "NumberOfPoints"))
        .and_then(|s| s.parse::<usize>().ok())
        .ok_or_else(|| bad(path, "no Piece with NumberOfPoints"))?;
    let time = data_array(path, text, "TimeValue", 1)?[0];
    let step = data_array(path, text, "Step", 1)?[0] as u64;
    let triples =
        |v: Vec<f64>| -> Vec<[f64; 3]> { v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect() };
    let pos = triples(data_array(path, text, "Points", 3 * n)?);
    // A 2D run writes z = 0 for every grain; its spin sits in omega's z.
    let dim = if pos.iter().all(|p| p[2] == 0.0) && n > 0 {
        2
    } else {
        3
    };
    Ok(Frame {
        step,
        time,
        dim,
        box_lo: [f64::NAN; 3],
        box_hi: [f64::NAN; 3],
        periodic: [false; 3],
        id: data_array(path, text, "id", n)?
            .into_iter()
            .map(|x| x as u64)
            .collect(),
        kind: data_array(path, text, "type", n)?
            .into_iter()
            .map(|x| x as u32)
            .collect(),
        radius: data_array(path, text, "radius", n)?,
        vel: triples(data_array(path, text, "velocity", 3 * n)?),
        omega: triples(data_array(path, text, "angular_velocity", 3 * n)?),
        // Saved only by runs that write their contacts (for `grains cg`).
        mass: match text.contains("Name=\"mass\"") {
            true => data_array(path, text, "mass", n)?,
            false => Vec::new(),
        },
        pos,
        // Written only by runs with rigid bodies.
        body: match text.contains("Name=\"body\"") {
            true => Some(
                data_array(path, text, "body", n)?
                    .into_iter()
                    .map(|x| x as u64)
                    .collect(),
            ),
            false => None,
        },
        orientation: match text.contains("Name=\"orientation\"") {
            true => Some(
                data_array(path, text, "orientation", 4 * n)?
                    .chunks_exact(4)
                    .map(|c| [c[0], c[1], c[2], c[3]])
                    .collect(),
            ),
            false => None,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::atomic::tests::scratch_dir;
    use crate::io::frame::tests::sample_2d;
    use crate::io::VtkSeries;

    #[test]
    fn frames_round_trip_through_the_series() {
        let dir = scratch_dir("vtkread");
        let mut series = VtkSeries::new(&dir).unwrap();
        let mut f = sample_2d();
        series.write(&f).unwrap();
        f.step += 10;
        f.time = 0.25;
        f.pos[0][0] = 1.0 / 3.0;
        series.write(&f).unwrap();
        let entries = read_series(&dir).unwrap();
        assert_eq!(entries.len(), 2);
        assert_eq!(entries[1].time, 0.25);
        let back = read_frame(&entries[1].path).unwrap();
        assert_eq!(back.pos, f.pos);
        assert_eq!(back.vel, f.vel);
        assert_eq!(back.omega, f.omega);
        assert_eq!(back.id, f.id);
        assert_eq!(back.kind, f.kind);
        assert_eq!(back.radius, f.radius);
        assert!(back.mass.is_empty());
        f.mass = vec![1.0 / 3.0, 2e-9, 7.0];
        series.write(&f).unwrap();
        let last = &read_series(&dir).unwrap()[2];
        assert_eq!(read_frame(&last.path).unwrap().mass, f.mass);
        assert_eq!((back.step, back.time, back.dim), (f.step, f.time, 2));
        assert_eq!((back.body, back.orientation), (None, None));
        // A run with bodies: its frames' body numbers and orientations.
        f.body = Some(vec![1, 0, 2]);
        f.orientation = Some(vec![
            [0.5, 0.5, -0.5, 0.5],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 0.6, 0.0, 0.8],
        ]);
        series.write(&f).unwrap();
        let last = read_frame(&read_series(&dir).unwrap()[3].path).unwrap();
        assert_eq!(last.body, f.body);
        assert_eq!(last.orientation, f.orientation);
    }

    #[test]
    fn missing_and_truncated_files_are_named() {
        let dir = scratch_dir("vtkread-bad");
        let err = read_series(&dir).unwrap_err().to_string();
        assert!(
            err.contains("frames.pvd") && err.contains("not found"),
            "{err}"
        );
        let mut series = VtkSeries::new(&dir).unwrap();
        series.write(&sample_2d()).unwrap();
        let entry = &read_series(&dir).unwrap()[0];
        let text = std::fs::read_to_string(&entry.path).unwrap();
        std::fs::write(&entry.path, &text[..text.len() / 2]).unwrap();
        let err = read_frame(&entry.path).unwrap_err().to_string();
        assert!(
            err.contains("frame_000000.vtp") && err.contains("truncated"),
            "{err}"
        );
        // A closed file with an array cut short.
        let short = text.replacen("0.45", "", 1);
        std::fs::write(&entry.path, short).unwrap();
        let err = read_frame(&entry.path).unwrap_err().to_string();
        assert!(err.contains("'radius' has 2 values, 3 expected"), "{err}");
        std::fs::remove_file(&entry.path).unwrap();
        let err = read_frame(&entry.path).unwrap_err().to_string();
        assert!(err.contains("frame file not found"), "{err}");
    }
}
