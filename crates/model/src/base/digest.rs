//! Content hashes: the SHA-256 of a file's bytes, in lower-case hex, as the records and the
//! provenance store it (an input a run reads, a mesh snapshot it saves, the manifest).

use sha2::{Digest, Sha256};

/// The SHA-256 of `bytes` as 64 lower-case hex digits.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}
