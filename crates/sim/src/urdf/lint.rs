//! A scan of a URDF's text before the XML parser (issue #41): the parser (`urdf-rs` on
//! serde-xml-rs) reports neither line nor element (`custom: invalid float literal`), takes an
//! SDF file for a robot of 0 links, and stops on leftovers of xacro. The scan names the line
//! and element of what it refuses, recognises SDF, MJCF and xacro files by their elements, and
//! repairs the few leftovers whose meaning is fixed, each reported:
//!
//! - `$(optenv NAME default…)` (xacro's optional environment variable): its default, as
//!   xacro gives it with `NAME` unset (the environment is not read);
//! - a `<material>` (or any element other than one shape) inside `<geometry>`: dropped, as
//!   pybullet does (materials are not simulated).
//!
//! It also records the moving joints whose `<limit>` gives no `lower` and no `upper`
//! ([`Scan::no_range`]): the parser makes them [0, 0]; see [`super::repair`].

use std::collections::HashSet;

use crate::error::{Result, SimError};

/// What the scan made of a URDF's text.
#[derive(Debug, Default)]
pub(crate) struct Scan {
    /// The text to parse: comments blanked (line numbers kept), repairs applied.
    pub text: String,
    /// One sentence per repair, with its line.
    pub warnings: Vec<String>,
    /// Revolute and prismatic joints whose `<limit>` (if any) gives neither `lower` nor `upper`.
    pub no_range: HashSet<String>,
}

/// One tag of the document (also of a COLLADA mesh: [`super::mesh_counts`]).
pub(super) struct Tag<'a> {
    /// 1-based line of its `<`.
    pub line: usize,
    /// Byte range of the whole tag, `<` to `>` inclusive.
    pub start: usize,
    pub end: usize,
    pub name: &'a str,
    /// The text after the name, up to (not including) `>` or `/>`; offset `attrs_at`.
    pub attrs: &'a str,
    attrs_at: usize,
    pub closing: bool,
    pub self_closing: bool,
}

/// `<!-- … -->` comments replaced by spaces, newlines kept (so lines still count).
pub(super) fn blank_comments(xml: &str) -> String {
    let mut out = String::with_capacity(xml.len());
    let mut rest = xml;
    while let Some(start) = rest.find("<!--") {
        out.push_str(&rest[..start]);
        let (comment, after) = match rest[start..].find("-->") {
            Some(end) => (&rest[start..start + end + 3], &rest[start + end + 3..]),
            None => (&rest[start..], ""),
        };
        out.extend(comment.chars().map(|c| if c == '\n' { '\n' } else { ' ' }));
        rest = after;
    }
    out.push_str(rest);
    out
}

/// The tags of `text` (comments already blanked), in order; `<?…?>` and `<!…>` skipped.
pub(super) fn tags(text: &str) -> Vec<Tag<'_>> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let (mut line, mut counted) = (1usize, 0usize);
    let mut at = 0;
    while let Some(offset) = text[at..].find('<') {
        let start = at + offset;
        line += bytes[counted..start].iter().filter(|b| **b == b'\n').count();
        counted = start;
        // The closing '>' outside quotes.
        let mut quote = None;
        let mut end = None;
        for (i, b) in bytes[start + 1..].iter().enumerate() {
            match (quote, *b) {
                (None, b'"' | b'\'') => quote = Some(*b),
                (Some(q), c) if c == q => quote = None,
                (None, b'>') => {
                    end = Some(start + 1 + i);
                    break;
                }
                _ => {}
            }
        }
        let Some(end) = end else { break };
        at = end + 1;
        let inner = &text[start + 1..end];
        if inner.starts_with('?') || inner.starts_with('!') {
            continue;
        }
        let closing = inner.starts_with('/');
        let body = inner.trim_start_matches('/');
        let self_closing = body.ends_with('/');
        let body = body.strip_suffix('/').unwrap_or(body);
        let name_len = body.find(|c: char| c.is_whitespace()).unwrap_or(body.len());
        let body_at = end - inner.len() + (inner.len() - inner.trim_start_matches('/').len());
        out.push(Tag {
            line,
            start,
            end: end + 1,
            name: &body[..name_len],
            attrs: &body[name_len..],
            attrs_at: body_at + name_len,
            closing,
            self_closing,
        });
    }
    out
}

/// `(name, value, byte range of the value in the tag's attrs)` of every attribute.
pub(super) fn attributes(attrs: &str) -> Vec<(&str, &str, usize, usize)> {
    let mut out = Vec::new();
    let bytes = attrs.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        while i < bytes.len() && bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        let name_start = i;
        while i < bytes.len() && bytes[i] != b'=' && !bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        let name = &attrs[name_start..i];
        while i < bytes.len() && bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        if i >= bytes.len() || bytes[i] != b'=' {
            i += 1;
            continue;
        }
        i += 1;
        while i < bytes.len() && bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        let Some(&quote) = bytes.get(i).filter(|q| **q == b'"' || **q == b'\'') else {
            continue;
        };
        let value_start = i + 1;
        let value_end = attrs[value_start..]
            .find(quote as char)
            .map_or(attrs.len(), |e| value_start + e);
        out.push((name, &attrs[value_start..value_end], value_start, value_end));
        i = value_end + 1;
    }
    out
}

/// The numeric attributes the physics reads: `(element, attribute, how many numbers)`.
const NUMBERS: &[(&str, &str, usize)] = &[
    ("origin", "xyz", 3),
    ("origin", "rpy", 3),
    ("axis", "xyz", 3),
    ("box", "size", 3),
    ("mesh", "scale", 3),
    ("sphere", "radius", 1),
    ("cylinder", "radius", 1),
    ("cylinder", "length", 1),
    ("capsule", "radius", 1),
    ("capsule", "length", 1),
    ("mass", "value", 1),
    ("inertia", "ixx", 1),
    ("inertia", "ixy", 1),
    ("inertia", "ixz", 1),
    ("inertia", "iyy", 1),
    ("inertia", "iyz", 1),
    ("inertia", "izz", 1),
    ("limit", "lower", 1),
    ("limit", "upper", 1),
    ("limit", "effort", 1),
    ("limit", "velocity", 1),
    ("dynamics", "damping", 1),
    ("dynamics", "friction", 1),
    ("mimic", "multiplier", 1),
    ("mimic", "offset", 1),
];

/// The shapes `<geometry>` may hold.
const SHAPES: [&str; 5] = ["box", "sphere", "cylinder", "capsule", "mesh"];

const RUN_XACRO: &str = "a xacro file, not URDF: run xacro first (`xacro robot.urdf.xacro > robot.urdf`)";

/// Scans `xml` (see the module doc). `origin` names the document in errors.
pub(crate) fn scan(xml: &str, origin: &str) -> Result<Scan> {
    let refuse = |reason: String| SimError::MalformedUrdf {
        origin: origin.to_string(),
        reason,
    };
    let text = blank_comments(xml);
    let all = tags(&text);
    let Some(root) = all.iter().find(|t| !t.closing) else {
        return Err(refuse("no XML element: not a URDF (its root is <robot>)".to_string()));
    };
    let format = match root.name {
        "robot" => None,
        "sdf" => Some("an SDF file (root <sdf>), not URDF: convert it to URDF first (pybullet's loadSDF reads it)"),
        "mujoco" => Some("an MJCF file (root <mujoco>), not URDF: convert it to URDF first"),
        n if n.starts_with("xacro:") => Some(RUN_XACRO),
        _ => None,
    };
    if let Some(what) = format {
        return Err(refuse(what.to_string()));
    }
    if root.name != "robot" {
        return Err(refuse(format!(
            "line {}: root element <{}>: not a URDF (its root is <robot>)",
            root.line, root.name
        )));
    }
    let mut out = Scan::default();
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    // The open elements: name and line.
    let mut stack: Vec<(&str, usize)> = Vec::new();
    // The joint being read: (name, type, whether its <limit> gave lower or upper).
    let mut joint: Option<(String, String, bool)> = None;
    // Start of an element dropped from a <geometry>, and its depth.
    let mut dropping: Option<(usize, usize)> = None;
    for tag in &all {
        let slash = if tag.self_closing { "/" } else { "" };
        let close = if tag.closing { "/" } else { "" };
        let element = format!("<{close}{}{}{slash}>", tag.name, tag.attrs.trim_end());
        let at = |what: String| refuse(format!("line {}, {element}: {what}", tag.line));
        if tag.name.starts_with("xacro:") {
            return Err(at(RUN_XACRO.to_string()));
        }
        if tag.closing {
            if let Some((start, depth)) = dropping
                && depth == stack.len()
            {
                edits.push((start, tag.end, String::new()));
                dropping = None;
            }
            match stack.pop() {
                Some((open, _)) if open == tag.name => {}
                Some((open, line)) => {
                    return Err(at(format!(
                        "closes <{open}>, opened on line {line}: the tags are not nested"
                    )));
                }
                None => return Err(at("closes no open element".to_string())),
            }
            if tag.name == "joint"
                && let Some((name, kind, ranged)) = joint.take()
                && (kind == "revolute" || kind == "prismatic")
                && !ranged
            {
                out.no_range.insert(name);
            }
            continue;
        }
        let attrs = attributes(tag.attrs);
        let value = |name: &str| attrs.iter().find(|a| a.0 == name).map(|a| a.1);
        // What the parser reads: <link>, <joint> and <material> and what they hold (not
        // <gazebo>, <transmission>, whose `$(find …)` plugin paths are not ours to refuse).
        let part = if stack.len() == 1 {
            Some(&tag.name)
        } else {
            stack.get(1).map(|(name, _)| name)
        };
        let read = matches!(part, Some(&"link" | &"joint" | &"material"));
        for (name, v, from, to) in attrs.iter().filter(|_| read) {
            if v.contains("${") {
                return Err(at(format!("{name}=\"{v}\" is a xacro expression: {RUN_XACRO}")));
            }
            if let Some(pos) = v.find("$(") {
                let close = v[pos..].find(')').map(|c| pos + c);
                let inner = close.map(|c| &v[pos + 2..c]);
                let default = inner.and_then(|i| i.trim().strip_prefix("optenv ")).map(|rest| {
                    let rest = rest.trim_start();
                    rest[rest.find(char::is_whitespace).unwrap_or(rest.len())..].trim()
                });
                let (Some(close), Some(default)) = (close, default) else {
                    return Err(at(format!("{name}=\"{v}\" is a xacro substitution: {RUN_XACRO}")));
                };
                let repaired = format!("{}{default}{}", &v[..pos], &v[close + 1..]);
                out.warnings.push(format!(
                    "line {}, <{} {name}>: xacro's {} read as its default \"{repaired}\" (the environment \
                     is not read; run xacro to set it)",
                    tag.line,
                    tag.name,
                    &v[pos..=close]
                ));
                edits.push((tag.attrs_at + from, tag.attrs_at + to, repaired));
            }
        }
        let in_robot_part = read && part != Some(&"material");
        for (element, attribute, count) in NUMBERS {
            if tag.name != *element || !in_robot_part {
                continue;
            }
            let Some(v) = value(attribute) else { continue };
            if v.contains("$(") {
                continue; // repaired above, checked by the parser
            }
            let words: Vec<&str> = v.split_whitespace().collect();
            if let Some(word) = words.iter().find(|w| w.parse::<f64>().is_err()) {
                return Err(at(format!("{attribute}: {word:?} is not a number; correct the file")));
            }
            if words.len() != *count {
                return Err(at(format!(
                    "{attribute}: {} numbers, expected {count}; correct the file",
                    words.len()
                )));
            }
        }
        if stack.len() == 1 && tag.name == "joint" {
            let name = value("name").unwrap_or("?").to_string();
            joint = Some((name, value("type").unwrap_or("").to_string(), false));
        }
        if tag.name == "limit"
            && stack.last().map(|t| t.0) == Some("joint")
            && let Some(j) = joint.as_mut()
        {
            if value("effort").is_none() || value("velocity").is_none() {
                return Err(at(
                    "effort and velocity are required (URDF: <limit effort velocity>)".to_string()
                ));
            }
            j.2 = value("lower").is_some() || value("upper").is_some();
        }
        if dropping.is_none() && stack.last().map(|t| t.0) == Some("geometry") && !SHAPES.contains(&tag.name) {
            out.warnings.push(format!(
                "line {}: <{}> inside <geometry> of link {:?} ignored (a <geometry> holds one shape)",
                tag.line,
                tag.name,
                link_name(&all, tag.start)
            ));
            if tag.self_closing {
                edits.push((tag.start, tag.end, String::new()));
            } else {
                dropping = Some((tag.start, stack.len()));
            }
        }
        if !tag.self_closing {
            stack.push((tag.name, tag.line));
        }
        if tag.self_closing && stack.len() == 1 && tag.name == "joint" {
            joint = None;
        }
    }
    if let Some((open, line)) = stack.last() {
        return Err(refuse(format!("line {line}: <{open}> is never closed")));
    }
    edits.sort_by_key(|e| e.0);
    let mut text_out = String::with_capacity(text.len());
    let mut last = 0;
    for (start, end, with) in edits {
        if start < last {
            continue;
        }
        text_out.push_str(&text[last..start]);
        text_out.push_str(&with);
        last = end;
    }
    text_out.push_str(&text[last..]);
    out.text = text_out;
    Ok(out)
}

/// Name of the `<link>` open at byte `at` (for messages).
fn link_name(all: &[Tag<'_>], at: usize) -> String {
    all.iter()
        .rev()
        .filter(|t| t.start < at && t.name == "link" && !t.closing)
        .find_map(|t| {
            attributes(t.attrs)
                .into_iter()
                .find(|a| a.0 == "name")
                .map(|a| a.1.to_string())
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reason(xml: &str) -> String {
        match scan(xml, "t") {
            Err(SimError::MalformedUrdf { reason, .. }) => reason,
            other => panic!("expected a refusal, got {other:?}"),
        }
    }

    #[test]
    fn recognises_other_formats() {
        assert!(reason("<?xml version='1.0'?>\n<sdf version='1.6'><model/></sdf>").contains("an SDF file"));
        assert!(reason("<mujoco model='x'/>").contains("an MJCF file"));
        let xacro = "<robot xmlns:xacro='x'>\n<xacro:property name='a' value='1'/>\n</robot>";
        let r = reason(xacro);
        assert!(
            r.starts_with("line 2, <xacro:property") && r.contains("run xacro first"),
            "{r}"
        );
        let r = reason("<robot>\n<link name='a'>\n<inertial><mass value='${m}'/></inertial></link></robot>");
        assert!(r.contains("line 3") && r.contains("xacro expression"), "{r}");
    }

    #[test]
    fn names_line_and_element_of_a_bad_number() {
        let xml = "<robot name='r'>\n<!-- a\ncomment -->\n<joint name='j' type='revolute'>\n  \
                   <limit effort='1' lower='-1.57.' upper='1'/>\n</joint></robot>";
        let r = reason(xml);
        assert!(
            r.starts_with("line 5, <limit effort='1' lower='-1.57.' upper='1'/>: lower: \"-1.57.\""),
            "{r}"
        );
        let r = reason("<robot>\n<joint name='j'><origin rpy='1 2 3 4'/></joint></robot>");
        assert!(r.contains("line 2") && r.contains("rpy: 4 numbers, expected 3"), "{r}");
    }

    #[test]
    fn names_the_line_of_tags_that_do_not_nest() {
        let r = reason("<robot>\n<joint name='j' type='fixed'>\n</joitn></robot>");
        assert_eq!(
            r,
            "line 3, </joitn>: closes <joint>, opened on line 2: the tags are not nested"
        );
        let r = reason("<robot>\n<link name='l'>\n</robot>");
        assert!(
            r.starts_with("line 3, </robot>: closes <link>, opened on line 2"),
            "{r}"
        );
        assert_eq!(reason("<robot>\n<link name='l'>"), "line 2: <link> is never closed");
        assert_eq!(
            reason("<robot></robot>\n</link>"),
            "line 2, </link>: closes no open element"
        );
    }

    #[test]
    fn repairs_optenv_and_stray_materials() {
        let xml = "<robot>\n<link name='l'><visual><geometry><box size='1 1 1'/>\n<material name='m'><color \
                   rgba='1 1 1 1'/></material></geometry></visual></link>\n<joint name='j' type='fixed'>\
                   <origin xyz=\"$(optenv POS 0.1 0 0.2)\"/></joint></robot>";
        let s = scan(xml, "t").unwrap();
        assert!(
            s.text.contains("xyz=\"0.1 0 0.2\"") && !s.text.contains("material"),
            "{}",
            s.text
        );
        assert_eq!(s.warnings.len(), 2, "{:?}", s.warnings);
        assert!(s.warnings[0].starts_with("line 3: <material> inside <geometry> of link \"l\""));
        assert!(s.warnings[1].starts_with("line 4") && s.warnings[1].contains("$(optenv POS 0.1 0 0.2)"));
        let r = reason("<robot><joint name='j'><origin xyz='$(arg x)'/></joint></robot>");
        assert!(r.contains("xacro substitution"), "{r}");
        // Not read by the parser: left alone.
        let gazebo = "<robot><gazebo><plugin filename='$(find pkg)/lib.so' rate='${r}'/></gazebo></robot>";
        assert!(scan(gazebo, "t").unwrap().warnings.is_empty());
    }

    #[test]
    fn records_joints_without_a_range() {
        let xml = "<robot><joint name='a' type='revolute'><limit effort='1' velocity='1'/></joint>\
                   <joint name='b' type='revolute'><limit lower='0' upper='0' effort='1' velocity='1'/></joint>\
                   <joint name='c' type='prismatic'/><joint name='d' type='fixed'/></robot>";
        let s = scan(xml, "t").unwrap();
        let mut names: Vec<_> = s.no_range.iter().cloned().collect();
        names.sort();
        assert_eq!(names, ["a"]);
    }
}
