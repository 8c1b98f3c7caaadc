//! The refinement history of a run: per level, the mesh's fingerprint, the elements marked and
//! the active set the contact solve started from. With the initial mesh it rebuilds any level's
//! mesh and solve exactly (`adapt::replay`), without storing meshes of millions of triangles:
//! the marks of a level cost a few bytes per run of equal flags.

use base64::Engine;
use serde::{Deserialize, Serialize};

/// A vector of flags, stored compactly: its length and the lengths of its alternating runs of
/// `false` and `true` (the first run is of `false` and may be empty), each as an unsigned LEB128
/// varint, the bytes in base64. Marks of the maximum strategy come in long runs along the
/// element numbering, so a level of 400 000 elements takes tens of kilobytes.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Flags {
    pub len: usize,
    pub runs: String,
}

/// Flags that do not decode: bad base64, a truncated varint, or runs that do not add up to the
/// length.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("stored flags do not decode: {0}")]
pub struct BadFlags(pub String);

impl Flags {
    pub fn encode(flags: &[bool]) -> Self {
        let mut bytes = Vec::new();
        let mut current = false;
        let mut run = 0u64;
        for &f in flags {
            if f != current {
                push_varint(&mut bytes, run);
                current = f;
                run = 0;
            }
            run += 1;
        }
        push_varint(&mut bytes, run);
        Flags { len: flags.len(), runs: base64::engine::general_purpose::STANDARD.encode(bytes) }
    }

    pub fn decode(&self) -> Result<Vec<bool>, BadFlags> {
        let bytes = base64::engine::general_purpose::STANDARD.decode(&self.runs).map_err(|e| BadFlags(e.to_string()))?;
        let mut flags = Vec::with_capacity(self.len);
        let (mut pos, mut current) = (0, false);
        while pos < bytes.len() {
            let (run, next) = read_varint(&bytes, pos).ok_or_else(|| BadFlags(format!("a varint is cut off at byte {pos}")))?;
            if flags.len() as u64 + run > self.len as u64 {
                return Err(BadFlags(format!("the runs exceed the length {}", self.len)));
            }
            flags.resize(flags.len() + run as usize, current);
            current = !current;
            pos = next;
        }
        if flags.len() != self.len {
            return Err(BadFlags(format!("the runs add up to {}, not to the length {}", flags.len(), self.len)));
        }
        Ok(flags)
    }
}

fn push_varint(bytes: &mut Vec<u8>, mut v: u64) {
    loop {
        let low = (v & 0x7f) as u8;
        v >>= 7;
        if v == 0 {
            bytes.push(low);
            return;
        }
        bytes.push(low | 0x80);
    }
}

/// The varint at `pos` and the position after it; None if the bytes end inside it.
fn read_varint(bytes: &[u8], mut pos: usize) -> Option<(u64, usize)> {
    let mut v = 0u64;
    for shift in (0..64).step_by(7) {
        let b = *bytes.get(pos)?;
        pos += 1;
        v |= u64::from(b & 0x7f) << shift;
        if b & 0x80 == 0 {
            return Some((v, pos));
        }
    }
    None
}

/// One level of a run's history.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct LevelHistory {
    pub level: usize,
    pub n_elements: usize,
    /// `Mesh::fingerprint` of the level's mesh.
    pub mesh: String,
    /// The active set the contact solve started from (the previous level's, transferred); None
    /// at level 0 and without warm starts.
    pub initial_active: Option<Flags>,
    /// The elements marked for refinement (also at the last level, not refined).
    pub marks: Flags,
}

/// A run's refinement history, one entry per level solved.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct History {
    pub levels: Vec<LevelHistory>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_round_trip() {
        let cases: Vec<Vec<bool>> =
            vec![vec![], vec![true], vec![false], vec![true; 300], (0..1000).map(|i| i % 7 == 0 || (200..500).contains(&i)).collect()];
        for flags in cases {
            let enc = Flags::encode(&flags);
            assert_eq!(enc.decode().unwrap(), flags);
        }
    }

    #[test]
    fn bad_flags_are_errors() {
        let good = Flags::encode(&[true, false, false]);
        assert!(Flags { len: 4, ..good.clone() }.decode().is_err());
        assert!(Flags { len: 2, ..good.clone() }.decode().is_err());
        assert!(Flags { len: 3, runs: "!!".into() }.decode().is_err());
        // a varint whose continuation bit promises a byte that is not there
        let cut = base64::engine::general_purpose::STANDARD.encode([0x80u8]);
        assert!(Flags { len: 0, runs: cut }.decode().is_err());
    }

    #[test]
    fn long_runs_are_short() {
        let flags: Vec<bool> = (0..400_000).map(|i| (i / 1000) % 2 == 0).collect();
        assert!(Flags::encode(&flags).runs.len() < 2000);
    }
}
