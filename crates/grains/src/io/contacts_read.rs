//! Reads back the contacts a run wrote (`contacts/contacts_NNNNN.csv`, the
//! layout of [`super::contacts_out`]) into a [`Snapshot`] whose grains are
//! already there, for `grains cg`.
//!
//! Numbers are read as written (shortest round-trip decimals), so a pair
//! contact comes back bit for bit; a wall contact's force is its normal
//! and tangential parts added again, which can differ from the force the
//! run held in the last bit.

use super::contact_records::{add, ContactRecord, Snapshot, WallRecord};
use super::contacts_out::CONTACT_COLUMNS;
use crate::error::{Error, Result};
use rustc_hash::FxHashMap;
use std::path::Path;

/// Adds the contacts of `path` to `s`, whose grains (`s.id`) must hold
/// every id the file names.
pub fn read_contacts_csv(path: &Path, s: &mut Snapshot) -> Result<()> {
    let text = std::fs::read_to_string(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => Error::input(format!(
            "{}: contacts file not found (listed in contacts.pvd; was the run directory \
             changed?)",
            path.display()
        )),
        _ => Error::io(path, e),
    })?;
    let mut lines = text.lines();
    if lines.next() != Some(CONTACT_COLUMNS) {
        return Err(Error::input(format!(
            "{}: not a grains contacts CSV (its header is not \"{CONTACT_COLUMNS}\")",
            path.display()
        )));
    }
    let index: FxHashMap<u64, usize> = s.id.iter().enumerate().map(|(i, &id)| (id, i)).collect();
    for (k, line) in lines.enumerate() {
        let row = k + 2;
        let bad = |what: String| Error::input(format!("{}: line {row}: {what}", path.display()));
        let cols: Vec<&str> = line.split(',').collect();
        if cols.len() != 20 {
            return Err(bad(format!("{} columns, 20 expected", cols.len())));
        }
        let grain = |c: &str| -> Result<(u64, usize)> {
            let id = c
                .parse::<u64>()
                .map_err(|_| bad(format!("grain id '{c}' is not a whole number")))?;
            let i = index.get(&id).copied().ok_or_else(|| {
                bad(format!(
                    "grain {id} is not in the frame of the same time (frames and contacts of \
                     different runs?)"
                ))
            })?;
            Ok((id, i))
        };
        let mut nums = [0.0; 16];
        for (x, c) in nums.iter_mut().zip(&cols[4..]) {
            *x = c
                .parse::<f64>()
                .map_err(|_| bad(format!("'{c}' is not a number")))?;
        }
        let v = |at: usize| [nums[at], nums[at + 1], nums[at + 2]];
        let (a, a_index) = grain(cols[0])?;
        if cols[1].is_empty() {
            let wall = cols[2]
                .parse::<usize>()
                .map_err(|_| bad(format!("wall index '{}' is not a whole number", cols[2])))?;
            s.walls.push(WallRecord {
                id: a,
                index: a_index,
                wall,
                wall_name: cols[3].to_string(),
                point: v(0),
                normal: v(6),
                force: add(v(9), v(12)),
                overlap: nums[15],
            });
        } else {
            let (b, b_index) = grain(cols[1])?;
            s.contacts.push(ContactRecord {
                ids: [a, b],
                index: [a_index, b_index],
                point: v(0),
                branch: v(3),
                normal: v(6),
                force_n: v(9),
                force_t: v(12),
                overlap: nums[15],
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::atomic::tests::scratch_dir;
    use crate::io::contacts_out::contacts_csv_string;

    #[test]
    fn contacts_round_trip_through_the_csv() {
        let mut s = Snapshot {
            dim: 2,
            id: vec![4, 9, 11],
            pos: vec![[0.1, 0.2, 0.0], [0.3, 0.2, 0.0], [0.5, 0.05, 0.0]],
            vel: vec![[0.0; 3]; 3],
            mass: vec![1.0; 3],
            radius: vec![0.11, 0.1, 0.06],
            ..Snapshot::default()
        };
        s.contacts.push(ContactRecord {
            ids: [9, 4],
            index: [1, 0],
            point: [0.2 - 1e-3, 0.2, 0.0],
            branch: [0.2, 0.0, 0.0],
            normal: [1.0, 0.0, 0.0],
            force_n: [1.0 / 3.0, 0.0, 0.0],
            force_t: [0.0, -2e-7, 0.0],
            overlap: 0.01,
        });
        s.walls.push(WallRecord {
            id: 11,
            index: 2,
            wall: 0,
            wall_name: "floor".into(),
            point: [0.5, 0.0, 0.0],
            normal: [0.0, 1.0, 0.0],
            force: [0.25, 3.0, 0.0],
            overlap: 0.01,
        });
        let dir = scratch_dir("contacts-read");
        let path = dir.join("c.csv");
        std::fs::write(&path, contacts_csv_string(&s)).unwrap();
        let mut back = Snapshot {
            contacts: Vec::new(),
            walls: Vec::new(),
            ..s.clone()
        };
        read_contacts_csv(&path, &mut back).unwrap();
        assert_eq!(back, s);
        // A grain the frame lacks is named.
        back.id[0] = 5;
        let err = read_contacts_csv(&path, &mut back).unwrap_err().to_string();
        assert!(err.contains("line 2: grain 4 is not in the frame"), "{err}");
        std::fs::write(&path, "a,b\n").unwrap();
        let err = read_contacts_csv(&path, &mut back).unwrap_err().to_string();
        assert!(err.contains("not a grains contacts CSV"), "{err}");
    }
}
