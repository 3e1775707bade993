//! VTK XML output for ParaView: one PolyData file (`.vtp`) per frame, and a
//! `.pvd` collection listing them with their times.
//!
//! Layout under the output directory:
//! `frames.pvd` and `frames/frame_000000.vtp`, `frames/frame_000001.vtp`, …
//! Data arrays are written in the ASCII format with full `f64` precision.
//!
//! In pieces (`output.frames_layout = "pieces"`), a frame is a parallel
//! PolyData file `frames/frame_NNNNNN.pvtp` that lists one piece per rank,
//! `frames/piece_<step>_<rank>.vtp` (a `.vtp` as above holding that rank's
//! own grains), and frames.pvd lists the `.pvtp` files. Each rank writes
//! its piece, so no rank formats the whole frame; the ranks must share the
//! output directory's file system.

use super::atomic::write_atomic;
use super::frame::Frame;
use super::Num;
use crate::error::{Error, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Renders one frame as a VTK XML PolyData document. Every particle is a
/// point and a vertex cell, so ParaView shows them without a filter (use the
/// "Point Gaussian" representation with `radius` as the scale array).
pub fn vtp_string(frame: &Frame) -> String {
    frame.check_lengths();
    let n = frame.len();
    let mut s = String::with_capacity(200 + n * 200);
    s.push_str("<?xml version=\"1.0\"?>\n");
    s.push_str(
        "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
    );
    s.push_str("  <PolyData>\n");
    s.push_str("    <FieldData>\n");
    let _ = writeln!(
        s,
        "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">{}</DataArray>",
        Num(frame.time)
    );
    let _ = writeln!(
        s,
        "      <DataArray type=\"Int64\" Name=\"Step\" NumberOfTuples=\"1\" format=\"ascii\">{}</DataArray>",
        frame.step
    );
    s.push_str("    </FieldData>\n");
    let _ = writeln!(
        s,
        "    <Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">"
    );
    s.push_str("      <PointData Scalars=\"radius\" Vectors=\"velocity\">\n");
    let [radius, vel, omega, id, kind] = POINT_ARRAYS;
    let num = |v: &f64| Num(*v);
    array(&mut s, radius, frame.radius.iter().map(num));
    array(&mut s, vel, frame.vel.iter().flatten().map(num));
    array(&mut s, omega, frame.omega.iter().flatten().map(num));
    array(&mut s, id, frame.id.iter());
    array(&mut s, kind, frame.kind.iter());
    // Only with bodies, so frames of runs without clumps keep their bytes.
    if let Some(body) = &frame.body {
        array(&mut s, BODY_ARRAYS[0], body.iter());
    }
    if let Some(q) = &frame.orientation {
        array(&mut s, BODY_ARRAYS[1], q.iter().flatten().map(num));
    }
    if !frame.mass.is_empty() {
        array(&mut s, ("Float64", "mass", 1), frame.mass.iter().map(num));
    }
    s.push_str("      </PointData>\n");
    s.push_str("      <Points>\n");
    let points = ("Float64", "Points", 3);
    array(&mut s, points, frame.pos.iter().flatten().map(num));
    s.push_str("      </Points>\n");
    s.push_str("      <Verts>\n");
    array(&mut s, ("Int64", "connectivity", 1), 0..n);
    array(&mut s, ("Int64", "offsets", 1), 1..=n);
    s.push_str("      </Verts>\n");
    s.push_str("    </Piece>\n  </PolyData>\n</VTKFile>\n");
    s
}

/// The point arrays of a frame (type, name, components), in file order.
const POINT_ARRAYS: [(&str, &str, usize); 5] = [
    ("Float64", "radius", 1),
    ("Float64", "velocity", 3),
    ("Float64", "angular_velocity", 3),
    ("Int64", "id", 1),
    ("Int32", "type", 1),
];

/// The point arrays of a frame with rigid bodies, after [`POINT_ARRAYS`]:
/// each grain's body (numbered from 1, 0 for a free sphere) and its body's
/// orientation quaternion (w, x, y, z).
const BODY_ARRAYS: [(&str, &str, usize); 2] = [("Int64", "body", 1), ("Float64", "orientation", 4)];

/// The `.vtp` piece of `rank` for the frame at `step`, relative to frames/.
pub fn piece_name(step: u64, rank: usize) -> String {
    format!("piece_{step:012}_{rank:04}.vtp")
}

/// Writes `frame` (this rank's grains) as its piece of a parallel frame.
pub fn write_piece(out_dir: &Path, frame: &Frame, rank: usize) -> Result<()> {
    let path = out_dir.join("frames").join(piece_name(frame.step, rank));
    write_atomic(&path, vtp_string(frame).as_bytes())
}

/// A parallel PolyData document (`.pvtp`) for the frame at `step` made of
/// the pieces of `ranks` ranks, with the point arrays of [`vtp_string`]
/// (`body` and `orientation` too when the run has rigid `bodies`).
pub fn pvtp_string(step: u64, ranks: usize, bodies: bool) -> String {
    let mut s = String::from("<?xml version=\"1.0\"?>\n");
    s.push_str(
        "<VTKFile type=\"PPolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
    );
    s.push_str("  <PPolyData GhostLevel=\"0\">\n");
    s.push_str("    <PPointData Scalars=\"radius\" Vectors=\"velocity\">\n");
    let body_arrays = if bodies { &BODY_ARRAYS[..] } else { &[] };
    for &(ty, name, comps) in POINT_ARRAYS.iter().chain(body_arrays) {
        let _ = writeln!(
            s,
            "      <PDataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{comps}\"/>"
        );
    }
    s.push_str("    </PPointData>\n    <PPoints>\n");
    s.push_str("      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n");
    s.push_str("    </PPoints>\n");
    for rank in 0..ranks {
        let _ = writeln!(s, "    <Piece Source=\"{}\"/>", piece_name(step, rank));
    }
    s.push_str("  </PPolyData>\n</VTKFile>\n");
    s
}

/// Appends one ASCII `DataArray`, six values per line.
fn array<T: std::fmt::Display>(
    s: &mut String,
    (ty, name, comps): (&str, &str, usize),
    values: impl Iterator<Item = T>,
) {
    let _ = write!(
        s,
        "        <DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{comps}\" format=\"ascii\">"
    );
    for (k, v) in values.enumerate() {
        s.push_str(if k % 6 == 0 { "\n          " } else { " " });
        let _ = write!(s, "{v}");
    }
    s.push_str("\n        </DataArray>\n");
}

/// A ParaView collection file: a list of (time, file name relative to the
/// collection) entries, rewritten atomically whenever an entry is added.
#[derive(Clone, Debug)]
pub struct PvdCollection {
    pub path: PathBuf,
    pub entries: Vec<(f64, String)>,
}

impl PvdCollection {
    pub fn new(path: impl Into<PathBuf>) -> Self {
        PvdCollection {
            path: path.into(),
            entries: Vec::new(),
        }
    }

    /// Records an entry and rewrites the collection file.
    pub fn add(&mut self, time: f64, file: impl Into<String>) -> Result<()> {
        self.entries.push((time, file.into()));
        self.write()
    }

    pub fn to_xml(&self) -> String {
        let mut s = String::from("<?xml version=\"1.0\"?>\n");
        s.push_str("<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
        s.push_str("  <Collection>\n");
        for (t, f) in &self.entries {
            let _ = writeln!(
                s,
                "    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>",
                Num(*t),
                xml_escape(f)
            );
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        s
    }

    pub fn write(&self) -> Result<()> {
        write_atomic(&self.path, self.to_xml().as_bytes())
    }
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// A time series of frames: `frames/frame_NNNNNN.vtp` under `dir`, listed in
/// `dir/frames.pvd`.
#[derive(Clone, Debug)]
pub struct VtkSeries {
    pub dir: PathBuf,
    pub collection: PvdCollection,
    /// In pieces: the number of ranks (see the module notes).
    pub pieces: Option<usize>,
}

impl VtkSeries {
    /// Creates `out_dir/frames/` (and `out_dir`) if needed. Starts a new
    /// collection: frame files left from an earlier run are overwritten.
    pub fn new(out_dir: &Path) -> Result<Self> {
        let frames = out_dir.join("frames");
        std::fs::create_dir_all(&frames).map_err(|e| Error::io(&frames, e))?;
        Ok(VtkSeries {
            dir: out_dir.to_path_buf(),
            collection: PvdCollection::new(out_dir.join("frames.pvd")),
            pieces: None,
        })
    }

    /// Writes frames in pieces, one per rank of `ranks`.
    pub fn in_pieces(mut self, ranks: usize) -> Self {
        self.pieces = Some(ranks.max(1));
        self
    }

    /// In pieces, the frames come from `ranks` ranks (each writes its own
    /// piece); gathered frames stay gathered.
    pub fn set_ranks(&mut self, ranks: usize) {
        if self.pieces.is_some() {
            self.pieces = Some(ranks.max(1));
        }
    }

    /// Continues the series of a resumed run: the collection lists the
    /// frames written before the checkpoint (`entries`) and is rewritten so
    /// that frames written after it are dropped.
    pub fn resume(out_dir: &Path, entries: &[(f64, String)]) -> Result<Self> {
        let mut series = Self::new(out_dir)?;
        series.collection.entries = entries.to_vec();
        series.collection.write()?;
        Ok(series)
    }

    /// Number of frames written so far.
    pub fn len(&self) -> usize {
        self.collection.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.collection.entries.is_empty()
    }

    /// Path of frame number `index` (counting from 0).
    pub fn frame_path(&self, index: usize) -> PathBuf {
        self.dir.join(format!("frames/frame_{index:06}.vtp"))
    }

    /// Writes the next frame file atomically, then the updated `frames.pvd`.
    /// In pieces: the `.pvtp`; on one rank also the single piece, from
    /// `frame`; with several, each rank has written its own with
    /// [`write_piece`] (`frame` then gives only the time and step).
    pub fn write(&mut self, frame: &Frame) -> Result<()> {
        let Some(ranks) = self.pieces else {
            let rel = format!("frames/frame_{:06}.vtp", self.len());
            write_atomic(&self.dir.join(&rel), vtp_string(frame).as_bytes())?;
            return self.collection.add(frame.time, rel);
        };
        if ranks == 1 {
            write_piece(&self.dir, frame, 0)?;
        }
        let rel = format!("frames/frame_{:06}.pvtp", self.len());
        let text = pvtp_string(frame.step, ranks, frame.body.is_some());
        write_atomic(&self.dir.join(&rel), text.as_bytes())?;
        self.collection.add(frame.time, rel)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::atomic::tests::scratch_dir;
    use crate::io::frame::tests::sample_2d;

    /// The whitespace-separated values of the DataArray named `name`.
    fn data_array(xml: &str, name: &str) -> Vec<f64> {
        let start = xml
            .find(&format!("Name=\"{name}\""))
            .unwrap_or_else(|| panic!("no array {name}"));
        let body = &xml[start..];
        let open = body.find('>').unwrap() + 1;
        let close = body.find("</DataArray>").unwrap();
        body[open..close]
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect()
    }

    #[test]
    fn vtp_round_trips_numbers() {
        let f = sample_2d();
        let xml = vtp_string(&f);
        assert!(xml.contains("NumberOfPoints=\"3\""));
        assert!(xml.contains("NumberOfVerts=\"3\""));
        assert_eq!(data_array(&xml, "radius"), f.radius);
        let pts: Vec<f64> = f.pos.iter().flatten().copied().collect();
        assert_eq!(data_array(&xml, "Points"), pts);
        let vel: Vec<f64> = f.vel.iter().flatten().copied().collect();
        assert_eq!(data_array(&xml, "velocity"), vel);
        let om: Vec<f64> = f.omega.iter().flatten().copied().collect();
        assert_eq!(data_array(&xml, "angular_velocity"), om);
        assert_eq!(data_array(&xml, "id"), vec![1.0, 2.0, 7.0]);
        assert_eq!(data_array(&xml, "type"), vec![1.0, 1.0, 2.0]);
        assert_eq!(data_array(&xml, "connectivity"), vec![0.0, 1.0, 2.0]);
        assert_eq!(data_array(&xml, "offsets"), vec![1.0, 2.0, 3.0]);
        assert_eq!(data_array(&xml, "TimeValue"), vec![0.12]);
    }

    #[test]
    fn empty_frame_is_valid() {
        let f = Frame {
            dim: 3,
            ..Default::default()
        };
        let xml = vtp_string(&f);
        assert!(xml.contains("NumberOfPoints=\"0\""));
        assert!(data_array(&xml, "radius").is_empty());
    }

    #[test]
    fn series_writes_frames_and_collection() {
        let dir = scratch_dir("vtk-series");
        let mut series = VtkSeries::new(&dir).unwrap();
        let mut f = sample_2d();
        series.write(&f).unwrap();
        f.time = 0.5;
        series.write(&f).unwrap();
        assert_eq!(series.frame_path(1), dir.join("frames/frame_000001.vtp"));
        assert!(series.frame_path(1).exists());
        assert!(dir.join("frames/frame_000000.vtp").exists());
        let pvd = std::fs::read_to_string(dir.join("frames.pvd")).unwrap();
        assert!(pvd
            .contains("timestep=\"0.12\" group=\"\" part=\"0\" file=\"frames/frame_000000.vtp\""));
        assert!(
            pvd.contains("timestep=\"0.5\" group=\"\" part=\"0\" file=\"frames/frame_000001.vtp\"")
        );
        let names: Vec<_> = std::fs::read_dir(dir.join("frames")).unwrap().collect();
        assert_eq!(names.len(), 2, "no temporary files left behind");
    }

    #[test]
    fn pieces_on_one_rank_are_a_pvtp_and_its_piece() {
        let dir = scratch_dir("vtk-pieces");
        let mut series = VtkSeries::new(&dir).unwrap().in_pieces(1);
        let mut f = sample_2d();
        f.step = 40;
        series.write(&f).unwrap();
        let pvtp = std::fs::read_to_string(dir.join("frames/frame_000000.pvtp")).unwrap();
        assert!(pvtp.contains("<Piece Source=\"piece_000000000040_0000.vtp\"/>"));
        assert_eq!(pvtp.matches("<Piece ").count(), 1);
        // The parallel file declares every array the piece holds, alike.
        let piece =
            std::fs::read_to_string(dir.join("frames/piece_000000000040_0000.vtp")).unwrap();
        assert_eq!(piece, vtp_string(&f));
        for (ty, name, comps) in POINT_ARRAYS {
            let decl = format!("type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{comps}\"");
            assert!(pvtp.contains(&decl) && piece.contains(&decl), "{name}");
        }
        let pvd = std::fs::read_to_string(dir.join("frames.pvd")).unwrap();
        assert!(pvd.contains("file=\"frames/frame_000000.pvtp\""));
        assert_eq!(pvtp_string(40, 3, false).matches("<Piece ").count(), 3);
        assert!(!pvtp.contains("body") && !piece.contains("orientation"));
    }

    /// With bodies, a frame and its parallel file carry `body` and
    /// `orientation` (four components a point), as declared alike.
    #[test]
    fn frames_of_bodies_carry_body_and_orientation() {
        let dir = scratch_dir("vtk-bodies");
        let mut series = VtkSeries::new(&dir).unwrap().in_pieces(1);
        let mut f = sample_2d();
        f.body = Some(vec![1, 1, 0]);
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        f.orientation = Some(vec![
            [c, 0.0, 0.0, s],
            [c, 0.0, 0.0, s],
            [1.0, 0.0, 0.0, 0.0],
        ]);
        series.write(&f).unwrap();
        let pvtp = std::fs::read_to_string(dir.join("frames/frame_000000.pvtp")).unwrap();
        let piece =
            std::fs::read_to_string(dir.join("frames").join(piece_name(f.step, 0))).unwrap();
        for (ty, name, comps) in POINT_ARRAYS.iter().chain(&BODY_ARRAYS) {
            let decl = format!("type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{comps}\"");
            assert!(pvtp.contains(&decl) && piece.contains(&decl), "{name}");
        }
        let q = data_array(&piece, "orientation");
        assert_eq!(q.len(), 12);
        assert_eq!(q[..4], [c, 0.0, 0.0, s]);
        assert_eq!(q[8..], [1.0, 0.0, 0.0, 0.0]);
    }
}
