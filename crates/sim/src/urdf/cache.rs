//! The on-disk cache of mesh hulls: one small file per (mesh bytes, scale), named by their
//! SHA-256, in `$LATENTRL_CACHE_DIR`, else `$XDG_CACHE_HOME/latentrl/hulls` (when absolute), else
//! `~/.cache/latentrl/hulls`.
//!
//! A cache is only ever a shortcut, and never trusted (issue #38): the key is public (anyone
//! can hash a mesh), so an entry is used only if
//! - the folder is private: owned by us and not writable by group or others, and no folder
//!   above it writable by others without the sticky bit (else [`trusted`] says why, the loader
//!   warns and reads no entry);
//! - the entry is a regular file of at most [`MAX_CACHE_ENTRY_BYTES`], owned by us, not
//!   writable by group or others, whose counts match its bytes ([`read`]);
//! - its hull is the hull of the mesh it is filed under: checked against the mesh's points by
//!   `mesh::load_hull` (every hull vertex is a vertex of the scaled mesh, every mesh vertex lies
//!   inside the hull, the triangles close it).
//!
//! Any other entry is not used: the hull is computed again and the entry rewritten, with a
//! warning. A cache that cannot be written is skipped silently. Entries are written (mode
//! 0600, folders 0700) to a temporary file and renamed, so parallel loads (Ray workers) never
//! read half an entry.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

/// First bytes of an entry: the format, bumped whenever hulls are made differently.
const MAGIC: &[u8; 8] = b"LRHULL01";

/// The largest entry read (bytes): 16 MiB, a hull of about 450 000 vertices (real collision
/// meshes' hulls have hundreds to a few thousand). A larger hull is not cached.
pub const MAX_CACHE_ENTRY_BYTES: u64 = 16 << 20;

/// The default cache folder, or `None` when no home or cache directory is known.
pub fn default_folder() -> Option<PathBuf> {
    folder_from(|name| std::env::var_os(name))
}

/// The cache folder the variables read by `var` name. An empty variable counts as unset, as
/// does a relative `$XDG_CACHE_HOME` (the XDG base directory spec calls it invalid).
fn folder_from(var: impl Fn(&str) -> Option<std::ffi::OsString>) -> Option<PathBuf> {
    let env = |name: &str| var(name).filter(|v| !v.is_empty()).map(PathBuf::from);
    env("LATENTRL_CACHE_DIR")
        .or_else(|| {
            env("XDG_CACHE_HOME")
                .filter(|d| d.is_absolute())
                .map(|d| d.join("latentrl"))
        })
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

/// The user id this process runs as (the owner of `/proc/self`), where the system says.
#[cfg(unix)]
fn our_uid() -> Option<u32> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata("/proc/self").ok().map(|m| m.uid())
}

/// Why others could write what `meta` describes, if they can: "is owned by user 1001, not by
/// us (user 1000)", "is writable by other users (mode 777)" (group or others).
#[cfg(unix)]
fn others_can_write(meta: &std::fs::Metadata) -> Option<String> {
    use std::os::unix::fs::MetadataExt;
    let mode = meta.mode() & 0o7777;
    if let Some(us) = our_uid()
        && meta.uid() != us
    {
        return Some(format!("is owned by user {}, not by us (user {us})", meta.uid()));
    }
    (mode & 0o022 != 0).then(|| format!("is writable by other users (mode {mode:o})"))
}

/// Whether the hull cache in `folder` may be used: `Err` says why not (a sentence for a
/// warning). A folder that does not exist yet is fine (it is created private).
#[cfg(unix)]
pub(super) fn trusted(folder: &Path) -> Result<(), String> {
    use std::os::unix::fs::MetadataExt;
    let advice = "not used, hulls are computed anew (make it private: `chmod go-w`, or set \
                  LATENTRL_CACHE_DIR to a folder of your own)";
    if let Ok(meta) = std::fs::metadata(folder)
        && let Some(why) = others_can_write(&meta)
    {
        return Err(format!("hull cache folder {} {why}: {advice}", folder.display()));
    }
    // A folder above it that others may write (without the sticky bit of /tmp) lets them
    // replace the cache folder itself.
    let absolute = std::path::absolute(folder).unwrap_or_else(|_| folder.to_path_buf());
    for above in absolute.ancestors().skip(1) {
        let Ok(meta) = std::fs::metadata(above) else { continue };
        let mode = meta.mode() & 0o7777;
        if mode & 0o002 != 0 && mode & 0o1000 == 0 {
            return Err(format!(
                "hull cache folder {} lies in {}, which any user may write (mode {mode:o}): {advice}",
                folder.display(),
                above.display()
            ));
        }
    }
    Ok(())
}

/// Elsewhere than unix: no owners or modes to check.
#[cfg(not(unix))]
pub(super) fn trusted(_folder: &Path) -> Result<(), String> {
    Ok(())
}

/// Hull points, triangles and the source's triangle count, as stored.
pub(super) type Entry = (Vec<[f32; 3]>, Vec<[u32; 3]>, usize);

/// The entry `key` in `folder`: `Ok(None)` if there is none, `Err` (a sentence naming the
/// entry) if one is there but is not used: not a regular private file of at most
/// [`MAX_CACHE_ENTRY_BYTES`], another format, or counts that do not match its bytes. Whether
/// its hull is the mesh's is for the caller to check.
pub(super) fn read(folder: &Path, key: &str) -> Result<Option<Entry>, String> {
    let path = folder.join(key);
    let refused = |why: String| format!("hull cache entry {} {why}: not used", path.display());
    let (file, meta) = match crate::files::open_regular(&path, MAX_CACHE_ENTRY_BYTES, "a hull cache entry") {
        Err(_) if std::fs::symlink_metadata(&path).is_err() => return Ok(None),
        Err(why) => return Err(refused(why)),
        Ok(opened) => opened,
    };
    #[cfg(unix)]
    if let Some(why) = others_can_write(&meta) {
        return Err(refused(why));
    }
    let bytes = crate::files::read_opened(file, &meta, MAX_CACHE_ENTRY_BYTES, "a hull cache entry").map_err(refused)?;
    parse(&bytes).map(Some).map_err(refused)
}

/// An entry's bytes as points, triangles and source count, or why they are not one.
fn parse(bytes: &[u8]) -> Result<Entry, String> {
    let body = bytes
        .strip_prefix(MAGIC)
        .ok_or("is not a hull cache entry of this version")?;
    let word = |i: usize| u32::from_le_bytes([0, 1, 2, 3].map(|k| body[4 * i + k]));
    if body.len() < 12 {
        return Err(format!("has {} bytes, too few for its counts", bytes.len()));
    }
    let (n_points, n_triangles, source) = (word(0) as usize, word(1) as usize, word(2) as usize);
    let expected = 4 * (3 + 3 * n_points as u64 + 3 * n_triangles as u64);
    if body.len() as u64 != expected {
        return Err(format!(
            "declares {n_points} points and {n_triangles} triangles ({} bytes) but has {}",
            expected + MAGIC.len() as u64,
            bytes.len()
        ));
    }
    let points = (0..n_points)
        .map(|p| [0, 1, 2].map(|k| f32::from_bits(word(3 + 3 * p + k))))
        .collect();
    let start = 3 + 3 * n_points;
    let triangles: Vec<[u32; 3]> = (0..n_triangles)
        .map(|t| [0, 1, 2].map(|k| word(start + 3 * t + k)))
        .collect();
    if let Some(i) = triangles.iter().flatten().find(|&&i| i as usize >= n_points) {
        return Err(format!("has a triangle naming point {i} of {n_points}"));
    }
    Ok((points, triangles, source))
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
    if (MAGIC.len() + 12 + 12 * (points.len() + triangles.len())) as u64 > MAX_CACHE_ENTRY_BYTES {
        return;
    }
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
    let stored = private_dir(dir)
        .and_then(|()| private_file(&temp, &out))
        .and_then(|()| std::fs::rename(&temp, dir.join(key)));
    if stored.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
}

/// Creates `dir` (and missing folders above it) readable and writable by us only.
fn private_dir(dir: &Path) -> std::io::Result<()> {
    let mut builder = std::fs::DirBuilder::new();
    builder.recursive(true);
    #[cfg(unix)]
    std::os::unix::fs::DirBuilderExt::mode(&mut builder, 0o700);
    builder.create(dir)
}

/// Writes `bytes` to the new file `path`, readable and writable by us only.
fn private_file(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let mut options = std::fs::OpenOptions::new();
    options.write(true).create_new(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o600);
    options.open(path)?.write_all(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(vars: &[(&str, &str)]) -> Option<PathBuf> {
        folder_from(|name| vars.iter().find(|(n, _)| *n == name).map(|(_, v)| v.into()))
    }

    #[test]
    fn the_folder_follows_the_first_usable_variable() {
        let at_home = "/home/u/.cache/latentrl/hulls";
        let cases = [
            (None, at_home),
            (Some(("XDG_CACHE_HOME", "/c")), "/c/latentrl/hulls"),
            (Some(("XDG_CACHE_HOME", "rel/c")), at_home), // relative: invalid, as the XDG spec says
            (Some(("XDG_CACHE_HOME", "")), at_home),
            (Some(("LATENTRL_CACHE_DIR", "mine")), "mine/hulls"),
        ];
        for (var, expected) in cases {
            let vars: Vec<_> = [("HOME", "/home/u")].into_iter().chain(var).collect();
            assert_eq!(folder(&vars), Some(expected.into()), "{var:?}");
        }
        assert_eq!(folder(&[]), None);
    }
}
