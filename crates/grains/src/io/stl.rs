//! STL files (binary and ASCII) read as a list of triangles.
//!
//! The parsing is `stl_io`'s (it tells ASCII from binary and checks the
//! binary length); this module only names the file and the triangle in
//! every error and widens the single-precision vertices to `f64`.

use crate::error::{Error, Result};
use std::path::Path;

/// One triangle: its three vertices, in the file's order (the winding is
/// kept but not relied on: mesh walls are two-sided).
pub type StlTriangle = [[f64; 3]; 3];

/// Reads every triangle of the STL file at `path`. A missing or malformed
/// file is an input error naming the file (and the triangle where the
/// parser stopped); an empty file or one without triangles too.
pub fn read_stl(path: &Path) -> Result<Vec<StlTriangle>> {
    let bytes = std::fs::read(path)
        .map_err(|e| Error::input(format!("mesh file {}: cannot be read: {e}", path.display())))?;
    parse_stl(&bytes).map_err(|e| Error::input(format!("mesh file {}: {e}", path.display())))
}

/// [`read_stl`] on the bytes of a file; errors without the file name.
pub fn parse_stl(bytes: &[u8]) -> std::result::Result<Vec<StlTriangle>, String> {
    let mut cursor = std::io::Cursor::new(bytes);
    let reader = stl_io::create_stl_reader(&mut cursor)
        .map_err(|e| format!("not an STL file (neither ASCII nor binary): {e}"))?;
    let mut out = Vec::new();
    for (i, t) in reader.enumerate() {
        let t = t.map_err(|e| format!("triangle {i}: malformed: {e}"))?;
        out.push(t.vertices.map(|v| v.0.map(f64::from)));
    }
    if out.is_empty() {
        return Err("holds no triangles".into());
    }
    Ok(out)
}

/// The bytes of a binary STL holding `triangles` (vertices rounded to
/// single precision, normals from the winding), for tools and tests.
pub fn binary_stl(triangles: &[StlTriangle]) -> Vec<u8> {
    let mut out = vec![0u8; 80];
    out.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    for t in triangles {
        let [a, b, c] = t.map(glam::DVec3::from_array);
        let n = (b - a).cross(c - a).normalize_or_zero();
        for v in [n, a, b, c] {
            for x in v.to_array() {
                out.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&[0, 0]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "solid two
facet normal 0 0 1
  outer loop
    vertex 0 0 0
    vertex 1 0 0
    vertex 0 1 0
  endloop
endfacet
facet normal 0 0 1
  outer loop
    vertex 1 0 0
    vertex 1 1 0
    vertex 0 1 0.5
  endloop
endfacet
endsolid two
";

    #[test]
    fn ascii_and_binary_give_the_same_triangles() {
        let a = parse_stl(ASCII.as_bytes()).unwrap();
        assert_eq!(a.len(), 2);
        assert_eq!(a[1], [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.5]]);
        let b = parse_stl(&binary_stl(&a)).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn malformed_files_are_refused_with_the_triangle() {
        assert!(parse_stl(b"").is_err());
        // A binary file that promises two triangles and holds one.
        let a = parse_stl(ASCII.as_bytes()).unwrap();
        let mut bin = binary_stl(&a);
        bin.truncate(84 + 50 + 10);
        let e = parse_stl(&bin).unwrap_err();
        assert!(e.contains("triangle 1") || e.contains("not an STL"), "{e}");
        // ASCII with a missing coordinate in the second facet.
        let bad = ASCII.replace("vertex 1 1 0\n", "vertex 1 1\n");
        let e = parse_stl(bad.as_bytes()).unwrap_err();
        assert!(e.contains("STL") || e.contains("triangle"), "{e}");
    }

    #[test]
    fn a_missing_file_names_itself() {
        let e = read_stl(Path::new("/no/such/hopper.stl")).unwrap_err();
        assert!(e.to_string().contains("/no/such/hopper.stl"), "{e}");
    }
}
