//! The on-disk cache of mesh hulls: one small file per (mesh bytes, scale), named by their
//! SHA-256, in `$LATENTRL_CACHE_DIR`, else `$XDG_CACHE_HOME/latentrl/hulls`, else
//! `~/.cache/latentrl/hulls`.
//!
//! A cache is only ever a shortcut: an entry that is missing, truncated or from another
//! format version is ignored (the hull is computed again), and a cache that cannot be
//! written is skipped silently. Entries are written to a temporary file and renamed, so
//! parallel loads (Ray workers) never read half an entry.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

/// First bytes of an entry: the format, bumped whenever hulls are made differently.
const MAGIC: &[u8; 8] = b"LRHULL01";

/// The default cache folder, or `None` when no home or cache directory is known.
pub fn default_folder() -> Option<PathBuf> {
    let env = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty()).map(PathBuf::from);
    env("LATENTRL_CACHE_DIR")
        .or_else(|| env("XDG_CACHE_HOME").map(|d| d.join("latentrl")))
        .or_else(|| env("HOME").map(|d| d.join(".cache").join("latentrl")))
        .map(|d| d.join("hulls"))
}

/// The entry name of a mesh file's bytes at `scale`.
pub(super) fn key(bytes: &[u8], scale: [f64; 3]) -> String {
    let mut hash = Sha256::new();
    hash.update(MAGIC);
    for s in scale {
        hash.update(s.to_le_bytes());
    }
    hash.update(bytes);
    hash.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// Hull points, triangles and the source's triangle count, as stored.
type Entry = (Vec<[f32; 3]>, Vec<[u32; 3]>, usize);

/// The entry `key` in `folder`, if it is there and whole.
pub(super) fn read(folder: &Path, key: &str) -> Option<Entry> {
    let bytes = std::fs::read(folder.join(key)).ok()?;
    let body = bytes.strip_prefix(MAGIC)?;
    let word = |i: usize| -> Option<u32> { Some(u32::from_le_bytes(body.get(4 * i..4 * i + 4)?.try_into().ok()?)) };
    let (n_points, n_triangles, source) = (word(0)? as usize, word(1)? as usize, word(2)? as usize);
    if body.len() != 4 * (3 + 3 * n_points + 3 * n_triangles) {
        return None;
    }
    let points = (0..n_points)
        .map(|p| Some([0, 1, 2].map(|k| word(3 + 3 * p + k).map(f32::from_bits))))
        .map(|p| p.and_then(|[x, y, z]| Some([x?, y?, z?])))
        .collect::<Option<Vec<_>>>()?;
    let start = 3 + 3 * n_points;
    let triangles = (0..n_triangles)
        .map(|t| Some([word(start + 3 * t)?, word(start + 3 * t + 1)?, word(start + 3 * t + 2)?]))
        .collect::<Option<Vec<_>>>()?;
    let in_range = triangles.iter().flatten().all(|&i| (i as usize) < n_points);
    in_range.then_some((points, triangles, source))
}

/// Stores an entry in `dir`; any failure (read-only disk) leaves the cache as it was.
pub(super) fn write(dir: &Path, key: &str, points: &[[f32; 3]], triangles: &[[u32; 3]], source_triangles: usize) {
    let (Ok(n_points), Ok(n_triangles), Ok(source)) = (
        u32::try_from(points.len()),
        u32::try_from(triangles.len()),
        u32::try_from(source_triangles),
    ) else {
        return;
    };
    let mut out = MAGIC.to_vec();
    for word in [n_points, n_triangles, source] {
        out.extend(word.to_le_bytes());
    }
    out.extend(points.iter().flatten().flat_map(|v| v.to_bits().to_le_bytes()));
    out.extend(triangles.iter().flatten().flat_map(|i| i.to_le_bytes()));
    let thread: String = format!("{:?}", std::thread::current().id())
        .chars()
        .filter(char::is_ascii_digit)
        .collect();
    let temp = dir.join(format!("{key}.{}.{thread}.tmp", std::process::id()));
    let stored = std::fs::create_dir_all(dir)
        .and_then(|()| std::fs::write(&temp, &out))
        .and_then(|()| std::fs::rename(&temp, dir.join(key)));
    if stored.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
}
