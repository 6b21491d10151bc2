//! The counts a mesh file declares, checked against the bytes it holds before the reader
//! allocates for them (issue #38).
//!
//! `mesh-loader` 0.1.13 trusts them: a COLLADA `<float_array count>` or `<polylist count>` is a
//! `Vec::with_capacity`, a `<triangles count>` times its inputs' stride a `reserve`, so a 1 KB
//! file declaring 2·10⁹ values asked for gigabytes and aborted the process (a failed allocation
//! is no panic: nothing catches it); an `<accessor count stride>` past the end of its array is an
//! `assert!`, and the product overflows its u32. A binary STL's triangle count is not read at
//! all (the reader counts the 50-byte records present), so a file cut short at a record boundary
//! loaded as part of its mesh.
//!
//! The rules, each refusal naming the element and its line:
//! - an array (`float_array`, `int_array`, `Name_array`, …): `count` at most the values its text
//!   holds;
//! - an `accessor`: `stride` ≥ 1, and `count × stride` at most the values of the array it names;
//! - `triangles`, `lines`: `count × 3 (2) × stride` at most the indices of their `<p>`, the stride
//!   being the largest `<input offset>` + 1; `polylist`: `count` at most its `<vcount>` values and
//!   their sum × stride at most the indices of `<p>`; `polygons`, `trifans`, `tristrips`,
//!   `linestrips`: `count` at most their `<p>` and `<ph>` elements;
//! - no `<!ENTITY` (an entity can expand to elements this scan does not see) and no entity
//!   reference in a `count`, `stride` or `offset`;
//! - a binary STL: the triangle count of its header at most the records present (fewer is
//!   common: some exporters write 0);
//! - the triangles declared (COLLADA `triangles` and `polylist`) or present (binary STL): at most
//!   [`MAX_MESH_TRIANGLES`].
//!
//! Values are counted as the reader splits them (on whitespace); where this scan and the XML
//! parser could disagree (CDATA, entities), it counts fewer, so it refuses rather than misses.

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::Path;

use super::lint::{Tag, attributes, blank_comments, tags};
use super::mesh::{MAX_MESH_TRIANGLES, too_many_triangles};

/// The formats `mesh-loader` reads, decided as it decides (its `detect_file_type`).
#[derive(Debug, PartialEq)]
enum Format {
    Stl,
    Collada,
    Other,
}

/// The format `mesh-loader` 0.1.13 reads `bytes` as: by the extension (exactly `stl`/`STL`,
/// `dae`/`DAE`, `obj`/`OBJ`), else by the first `solid` or `<COLLADA` in the first 1024 bytes.
fn format(path: &Path, bytes: &[u8]) -> Format {
    match path.extension().and_then(|e| e.to_str()) {
        Some("stl" | "STL") => return Format::Stl,
        Some("dae" | "DAE") => return Format::Collada,
        Some("obj" | "OBJ") => return Format::Other,
        _ => {}
    }
    let head = &bytes[..bytes.len().min(1024)];
    for i in 0..head.len() {
        if head[i..].starts_with(b"solid") {
            return Format::Stl;
        }
        if head[i..].starts_with(b"<COLLADA") {
            return Format::Collada;
        }
    }
    Format::Other
}

/// Refuses a mesh file whose declared counts exceed what it holds (the module doc); `path`
/// gives the format as the reader decides it. Nothing is allocated in proportion to a count.
pub(super) fn check(bytes: &[u8], path: &Path) -> Result<(), String> {
    match format(path, bytes) {
        Format::Stl => check_stl(bytes),
        Format::Collada => check_collada(&decode(bytes)?),
        Format::Other => Ok(()),
    }
}

/// A binary STL's header count against its 50-byte records; an ASCII STL declares nothing.
fn check_stl(bytes: &[u8]) -> Result<(), String> {
    const HEADER: usize = 84;
    const RECORD: usize = 50;
    let text = |b: &u8| b.is_ascii_graphic() || b.is_ascii_whitespace();
    let ascii = bytes.trim_ascii_start().starts_with(b"solid") && bytes.iter().all(text);
    if ascii || bytes.len() < HEADER {
        return Ok(()); // an ASCII STL, or too short for the reader (it says so)
    }
    let declared = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
    let present = (bytes.len() - HEADER) / RECORD;
    if declared > present {
        return Err(format!(
            "is a binary STL whose header declares {declared} triangles ({} bytes) but that holds {present} \
             ({} bytes): cut short?",
            HEADER as u64 + RECORD as u64 * declared as u64,
            bytes.len()
        ));
    }
    if present > MAX_MESH_TRIANGLES {
        return Err(too_many_triangles(present));
    }
    Ok(())
}

/// The text of a COLLADA file as `mesh-loader` decodes it: UTF-8 (a BOM skipped), or UTF-16
/// with a BOM; anything else is refused here (the reader would refuse it too).
fn decode(bytes: &[u8]) -> Result<Cow<'_, str>, String> {
    let utf16 = |body: &[u8], word: fn([u8; 2]) -> u16| {
        let units: Vec<u16> = body.chunks(2).map(|c| word([c[0], *c.get(1).unwrap_or(&0)])).collect();
        String::from_utf16(&units).map(Cow::Owned).ok()
    };
    let text = if let Some(body) = bytes.strip_prefix(b"\xEF\xBB\xBF") {
        std::str::from_utf8(body).ok().map(Cow::Borrowed)
    } else if bytes.starts_with(b"\x00\x00\xFE\xFF") || bytes.starts_with(b"\xFF\xFE\x00\x00") {
        None
    } else if let Some(body) = bytes.strip_prefix(b"\xFE\xFF") {
        utf16(body, u16::from_be_bytes)
    } else if let Some(body) = bytes.strip_prefix(b"\xFF\xFE") {
        utf16(body, u16::from_le_bytes)
    } else {
        std::str::from_utf8(bytes).ok().map(Cow::Borrowed)
    };
    text.ok_or_else(|| "is a COLLADA file that is neither UTF-8 nor UTF-16 text".to_string())
}

/// The local name of a tag (`collada:p` → `p`).
fn local<'a>(tag: &Tag<'a>) -> &'a str {
    tag.name.rsplit(':').next().unwrap_or(tag.name)
}

/// The values of a tag's text: whitespace-separated words up to the next tag that closes
/// (CDATA markers are not values).
fn words<'a>(text: &'a str, all: &[Tag<'_>], at: usize) -> impl Iterator<Item = &'a str> {
    let tag = &all[at];
    let end = match tag.self_closing {
        true => tag.end,
        false => all[at + 1..].iter().find(|t| t.closing).map_or(text.len(), |t| t.start),
    };
    text[tag.end.min(end)..end]
        .split_ascii_whitespace()
        .map(|w| w.trim_start_matches("<![CDATA[").trim_end_matches("]]>"))
        .filter(|w| !w.is_empty())
}

/// Attribute `name` of a tag as a number: `Ok(None)` if absent or not a number (the reader
/// refuses those), an error for an entity reference (the reader expands it; this scan does not).
fn number(tag: &Tag<'_>, name: &str) -> Result<Option<u64>, String> {
    let Some((_, value, _, _)) = attributes(tag.attrs).into_iter().find(|(n, ..)| *n == name) else {
        return Ok(None);
    };
    if value.contains('&') {
        return Err(format!(
            "line {}: <{}> has an entity reference in {name}={value:?}: write the number",
            tag.line, tag.name
        ));
    }
    Ok(value.parse::<u64>().ok())
}

/// Checks every count of a COLLADA document against the values it holds (the module doc).
fn check_collada(text: &str) -> Result<(), String> {
    if text.contains("<!ENTITY") {
        return Err("is a COLLADA file declaring XML entities (<!ENTITY>), which latentrl does not read".to_string());
    }
    let clean = blank_comments(text);
    let all = tags(&clean);
    let refuse = |tag: &Tag<'_>, what: String| Err(format!("line {}: <{}> {what}", tag.line, tag.name));
    // Arrays first: accessors name them by id, before or after.
    let mut arrays: HashMap<&str, u64> = HashMap::new();
    for (i, tag) in all.iter().enumerate() {
        if tag.closing || !local(tag).ends_with("_array") {
            continue;
        }
        let held = words(&clean, &all, i).count() as u64;
        // An empty array is read as empty whatever its count (some exporters write them).
        if let Some(count) = number(tag, "count")?
            && held > 0
            && count > held
        {
            return refuse(tag, format!("declares count={count} values but holds {held}"));
        }
        if let Some((_, id, ..)) = attributes(tag.attrs).into_iter().find(|(n, ..)| *n == "id") {
            arrays.insert(id, held);
        }
    }
    let mut declared_triangles = 0u64;
    for (i, tag) in all.iter().enumerate() {
        if tag.closing {
            continue;
        }
        match local(tag) {
            "accessor" => {
                let count = number(tag, "count")?.unwrap_or(0);
                let stride = number(tag, "stride")?.unwrap_or(1);
                if stride == 0 {
                    return refuse(tag, "has stride=0: a stride is at least 1".to_string());
                }
                let source = attributes(tag.attrs).into_iter().find(|(n, ..)| *n == "source");
                let id = source.map_or("", |(_, v, ..)| v.trim_start_matches('#'));
                let Some(&held) = arrays.get(id) else {
                    return refuse(tag, format!("reads source {id:?}, which is no array of the file"));
                };
                if count.saturating_mul(stride) > held {
                    return refuse(
                        tag,
                        format!("declares count={count} x stride={stride} values but its array {id:?} holds {held}"),
                    );
                }
            }
            kind @ ("triangles" | "lines" | "polylist" | "polygons" | "trifans" | "tristrips" | "linestrips") => {
                let Some(count) = number(tag, "count")? else { continue };
                let primitive = Primitive::read(&clean, &all, i, count)?;
                let per_face = match kind {
                    "triangles" => Some(3),
                    "lines" => Some(2),
                    _ => None,
                };
                let needed = match (kind, per_face) {
                    (_, Some(n)) => count.saturating_mul(n),
                    ("polylist", _) => primitive.vcount_sum,
                    _ => 0,
                };
                if kind == "polylist" && count > primitive.vcount_values {
                    return refuse(
                        tag,
                        format!(
                            "declares count={count} polygons but its <vcount> holds {}",
                            primitive.vcount_values
                        ),
                    );
                }
                if per_face.is_none() && kind != "polylist" && count > primitive.elements {
                    return refuse(
                        tag,
                        format!(
                            "declares count={count} but holds {} <p> and <ph> elements",
                            primitive.elements
                        ),
                    );
                }
                if needed.saturating_mul(primitive.stride) > primitive.indices {
                    return refuse(
                        tag,
                        format!(
                            "declares count={count}, {needed} vertices x {} inputs of indices, but its <p> holds {}",
                            primitive.stride, primitive.indices
                        ),
                    );
                }
                declared_triangles += match kind {
                    "triangles" => count,
                    "polylist" => primitive.polylist_triangles,
                    _ => 0,
                };
            }
            _ => {}
        }
    }
    if declared_triangles > MAX_MESH_TRIANGLES as u64 {
        return Err(too_many_triangles(
            usize::try_from(declared_triangles).unwrap_or(usize::MAX),
        ));
    }
    Ok(())
}

/// What a primitive element (`<triangles>`, `<polylist>`, …) holds, counted in its children.
#[derive(Default)]
struct Primitive {
    /// The largest `<input offset>` + 1: indices per vertex.
    stride: u64,
    /// Indices in its `<p>` elements.
    indices: u64,
    /// `<p>` and `<ph>` elements.
    elements: u64,
    /// Values of its `<vcount>`, and the sum of the first `count` of them.
    vcount_values: u64,
    vcount_sum: u64,
    /// Triangles of those polygons (a polygon of n ≥ 3 vertices is n − 2).
    polylist_triangles: u64,
}

impl Primitive {
    /// The children of the primitive element at `all[at]`, up to its closing tag.
    fn read(text: &str, all: &[Tag<'_>], at: usize, count: u64) -> Result<Self, String> {
        let mut out = Self {
            stride: 1,
            ..Self::default()
        };
        if all[at].self_closing {
            return Ok(out);
        }
        let name = local(&all[at]);
        let mut depth = 0usize;
        for (j, tag) in all.iter().enumerate().skip(at + 1) {
            if local(tag) == name {
                if tag.closing && depth == 0 {
                    break;
                }
                if !tag.self_closing {
                    depth = if tag.closing { depth - 1 } else { depth + 1 };
                }
            }
            if tag.closing {
                continue;
            }
            match local(tag) {
                "input" => {
                    let offset = number(tag, "offset")?.unwrap_or(0);
                    out.stride = out.stride.max(offset.saturating_add(1));
                }
                "p" | "ph" => {
                    out.elements += 1;
                    if local(tag) == "p" {
                        out.indices += words(text, all, j).count() as u64;
                    }
                }
                "vcount" => {
                    for (k, word) in words(text, all, j).enumerate() {
                        let n = word.parse::<u64>().unwrap_or(0);
                        out.vcount_values += 1;
                        if (k as u64) < count {
                            out.vcount_sum = out.vcount_sum.saturating_add(n);
                            out.polylist_triangles = out.polylist_triangles.saturating_add(n.saturating_sub(2));
                        }
                    }
                }
                _ => {}
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A COLLADA file of one `<triangles>` mesh: `array` floats declared as `declared`, an
    /// accessor of `accessor` points, `triangles` triangles over the indices `p`.
    fn dae(declared: u64, accessor: u64, triangles: u64, p: &str) -> String {
        format!(
            r##"<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<library_geometries><geometry id="g"><mesh>
<source id="pos"><float_array id="pos-array" count="{declared}">0 0 0 1 0 0 0 1 0 0 0 1</float_array>
<technique_common><accessor source="#pos-array" count="{accessor}" stride="3">
<param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
</accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#pos"/></vertices>
<triangles count="{triangles}"><input semantic="VERTEX" source="#v" offset="0"/><p>{p}</p></triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node><instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#s"/></scene>
</COLLADA>"##
        )
    }

    const TETRA: &str = "0 2 1 0 1 3 0 3 2 1 2 3";

    #[test]
    fn issue38_a_consistent_collada_passes() {
        assert_eq!(check(dae(12, 4, 4, TETRA).as_bytes(), Path::new("m.dae")), Ok(()));
    }

    #[test]
    fn issue38_collada_counts_beyond_the_bytes_are_refused_naming_the_element() {
        let at = Path::new("m.dae");
        let err = check(dae(2_000_000_000, 4, 4, TETRA).as_bytes(), at).unwrap_err();
        assert!(
            err.contains("<float_array> declares count=2000000000 values but holds 12"),
            "{err}"
        );
        let err = check(dae(12, 1 << 31, 4, TETRA).as_bytes(), at).unwrap_err();
        assert!(err.contains("<accessor> declares count=2147483648 x stride=3"), "{err}");
        let err = check(dae(12, 4, 2_000_000_000, TETRA).as_bytes(), at).unwrap_err();
        assert!(err.contains("<triangles> declares count=2000000000"), "{err}");
        assert!(err.starts_with("line 9: "), "{err}");
        let huge_offset = dae(12, 4, 4, TETRA).replace("offset=\"0\"", "offset=\"4294967295\"");
        let err = check(huge_offset.as_bytes(), at).unwrap_err();
        assert!(err.contains("x 4294967296 inputs"), "{err}");
        let zero_stride = dae(12, 4, 4, TETRA).replace("stride=\"3\"", "stride=\"0\"");
        assert!(check(zero_stride.as_bytes(), at).unwrap_err().contains("stride=0"));
        let entity = dae(12, 4, 4, TETRA).replace("count=\"12\"", "count=\"&#49;2\"");
        assert!(check(entity.as_bytes(), at).unwrap_err().contains("entity reference"));
        let declared = format!("<!DOCTYPE c [<!ENTITY e \"x\">]>{}", dae(12, 4, 4, TETRA));
        assert!(check(declared.as_bytes(), at).unwrap_err().contains("<!ENTITY>"));
        // Found by content too, whatever the extension.
        let err = check(dae(2_000_000_000, 4, 4, TETRA).as_bytes(), Path::new("m.mesh")).unwrap_err();
        assert!(err.contains("count=2000000000"), "{err}");
        // A comment is not an element.
        let commented =
            dae(12, 4, 4, TETRA).replace("<scene>", "<!-- <float_array count=\"99\"></float_array> --><scene>");
        assert_eq!(check(commented.as_bytes(), at), Ok(()));
    }

    #[test]
    fn issue38_polylists_are_checked_by_their_vcount() {
        let polylist = |count: u64, vcount: &str| {
            dae(12, 4, 4, TETRA).replace(
                &format!("<triangles count=\"4\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><p>{TETRA}</p></triangles>"),
                &format!("<polylist count=\"{count}\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><vcount>{vcount}</vcount><p>{TETRA}</p></polylist>"),
            )
        };
        let at = Path::new("m.dae");
        assert_eq!(check(polylist(4, "3 3 3 3").as_bytes(), at), Ok(()));
        let err = check(polylist(1_000_000_000, "3 3 3 3").as_bytes(), at).unwrap_err();
        assert!(
            err.contains("count=1000000000 polygons but its <vcount> holds 4"),
            "{err}"
        );
        let err = check(polylist(1, "4000000000").as_bytes(), at).unwrap_err();
        assert!(err.contains("4000000000 vertices"), "{err}");
    }

    #[test]
    fn issue38_a_binary_stl_declaring_more_triangles_than_it_holds_is_refused() {
        let mut stl = vec![0u8; 84 + 50];
        stl[80..84].copy_from_slice(&1u32.to_le_bytes());
        assert_eq!(check(&stl, Path::new("m.stl")), Ok(()));
        stl[80..84].copy_from_slice(&0u32.to_le_bytes()); // a zero count: common, accepted
        assert_eq!(check(&stl, Path::new("m.stl")), Ok(()));
        stl[80..84].copy_from_slice(&2_000_000_000u32.to_le_bytes());
        let err = check(&stl, Path::new("m.stl")).unwrap_err();
        assert!(err.contains("declares 2000000000 triangles"), "{err}");
        assert!(err.contains("holds 1 (134 bytes)"), "{err}");
        // A header starting with "solid" does not make a binary file ASCII.
        stl[..5].copy_from_slice(b"solid");
        assert!(check(&stl, Path::new("m.stl")).is_err());
        let ascii = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        assert_eq!(check(ascii, Path::new("m.stl")), Ok(()));
    }
}
