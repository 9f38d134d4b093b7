//! The byte-level pre-scan of an OBJ file, run before `tobj` sees it.
//!
//! `tobj` errors carry no line numbers and `tobj` can overflow or panic on absurd indices, so
//! every line is checked here first and each syntax or range problem is reported as
//! `file:line: problem` before anything is allocated from an index value. The scan also counts
//! elements (for the loader's limits), records `mtllib`/`usemtl` lines, collects warnings, and
//! writes the normalized copy of the file that `tobj` loads: vertex colours dropped, `l`/`p`
//! elements removed, keywords re-spaced, inline comments on element lines removed.

use std::path::Path;

use super::warn;
use crate::assets::error::AssetError;
use crate::assets::text::LossyLines;

/// Result of the byte-level pre-scan.
#[derive(Debug, Default)]
pub(super) struct Scan {
    /// Normalized OBJ text for `tobj`.
    pub(super) normalized: String,
    /// Line of each `mtllib` statement, in order.
    pub(super) mtllibs: Vec<usize>,
    /// `usemtl` names with their lines.
    pub(super) usemtls: Vec<(String, usize)>,
    pub(super) positions: usize,
    texcoords: usize,
    normals: usize,
    pub(super) faces: usize,
    pub(super) points: usize,
    pub(super) lines: usize,
    pub(super) warnings: Vec<String>,
}

/// The material name a nameless `usemtl` is given for `tobj`: no MTL material answers to it
/// (see `load_mtllib`), so its faces take the default material.
pub(super) const NO_MATERIAL: &str = "\u{fffd}no material\u{fffd}";

/// Statements that are valid OBJ but not supported (free-form geometry etc.).
const SILENTLY_IGNORED: &[&str] = &[
    "s",
    "mg",
    "lod",
    "shadow_obj",
    "trace_obj",
    "bevel",
    "c_interp",
    "d_interp",
];

/// Checks `bytes` (the contents of `path`) line by line; the first invalid line is an error.
pub(super) fn prescan(path: &Path, bytes: &[u8]) -> Result<Scan, AssetError> {
    let mut pre = Prescan {
        scan: Scan {
            normalized: String::with_capacity(bytes.len()),
            ..Default::default()
        },
        ..Default::default()
    };
    let mut text = LossyLines::default();
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let lineno = i + 1;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let decoded = text.decode(lineno, raw);
        pre.statement(path, lineno, decoded.trim())?;
    }
    Ok(pre.finish(path, &text))
}

/// The pre-scan's state while it reads the file: the [`Scan`] being built and what the
/// warnings at the end report.
#[derive(Default)]
struct Prescan {
    scan: Scan,
    /// Line of the first skipped point (`p`) or line (`l`) element.
    first_skipped: Option<usize>,
    /// Faces with more than three vertices.
    polygons: usize,
    /// Vertices whose colour values were dropped.
    colors: usize,
    /// Unsupported statements, and the first one with its line.
    unsupported: usize,
    first_unsupported: Option<(String, usize)>,
    /// Statements skipped because they name nothing (`usemtl` or `mtllib` alone).
    unnamed: Vec<(String, usize)>,
    /// The form (texture coordinates, normals) of the first face of the mesh being read (since
    /// the last `o`, `g` or `usemtl`, where tobj starts a mesh), its line, and whether a face of
    /// another form in it has been warned about.
    mesh_form: Option<([bool; 2], usize, bool)>,
}

impl Prescan {
    /// Checks and records one trimmed line.
    fn statement(&mut self, path: &Path, lineno: usize, line: &str) -> Result<(), AssetError> {
        let line = strip_inline_comment(line);
        let mut toks = line.split_whitespace();
        let Some(key) = toks.next() else {
            return Ok(());
        };
        let rest = line.get(key.len()..).unwrap_or("").trim();
        let err = |msg: String| AssetError::parse(path, lineno, msg);
        match key {
            k if k.starts_with('#') => {}
            "v" => self.vertex(toks).map_err(err)?,
            "vt" => self.texcoord(toks).map_err(err)?,
            "vn" => self.normal(toks).map_err(err)?,
            "f" => {
                let form = self.face(toks, rest).map_err(err)?;
                self.note_face_form(path, lineno, form);
            }
            "l" | "p" => {
                if key == "l" {
                    self.scan.lines += 1;
                } else {
                    self.scan.points += 1;
                }
                self.first_skipped.get_or_insert(lineno);
            }
            "o" | "g" => {
                self.mesh_form = None;
                push_line(&mut self.scan.normalized, &format!("{key} {rest}"));
            }
            "usemtl" | "mtllib" => {
                if key == "usemtl" {
                    self.mesh_form = None;
                }
                self.material_statement(key, rest, lineno);
            }
            k if SILENTLY_IGNORED.contains(&k) => {}
            k => {
                self.unsupported += 1;
                self.first_unsupported
                    .get_or_insert((k.to_string(), lineno));
            }
        }
        Ok(())
    }

    /// `v x y z [w]`, or `v x y z r g b [...]` with vertex colours (dropped).
    fn vertex<'a>(&mut self, toks: impl Iterator<Item = &'a str>) -> Result<(), String> {
        let vals: Vec<&str> = toks.take(8).collect();
        if vals.len() < 3 {
            return Err(format!("vertex has {} coordinates, need 3", vals.len()));
        }
        let mut out = String::from("v");
        for (j, t) in vals.iter().enumerate() {
            let is_w = vals.len() == 4 && j == 3;
            if j >= 3 && !is_w {
                self.colors += 1;
                break;
            }
            let v = parse_finite(t).map_err(|m| format!("vertex {m}"))?;
            if is_w && v == 0.0 {
                return Err("vertex w is zero".to_string());
            }
            out.push(' ');
            out.push_str(t);
        }
        push_line(&mut self.scan.normalized, &out);
        self.scan.positions += 1;
        Ok(())
    }

    /// `vt u [v [w]]`; a missing `v` is 0 and `w` is dropped.
    fn texcoord<'a>(&mut self, toks: impl Iterator<Item = &'a str>) -> Result<(), String> {
        let vals: Vec<&str> = toks.take(3).collect();
        let Some(u) = vals.first() else {
            return Err("texture coordinate has no values".to_string());
        };
        let v = vals.get(1).copied().unwrap_or("0");
        for t in [*u, v] {
            parse_finite(t).map_err(|m| format!("texture coordinate {m}"))?;
        }
        push_line(&mut self.scan.normalized, &format!("vt {u} {v}"));
        self.scan.texcoords += 1;
        Ok(())
    }

    /// `vn x y z`; extra components are dropped.
    fn normal<'a>(&mut self, toks: impl Iterator<Item = &'a str>) -> Result<(), String> {
        let vals: Vec<&str> = toks.take(4).collect();
        if vals.len() < 3 {
            return Err(format!("normal has {} components, need 3", vals.len()));
        }
        let mut out = String::from("vn");
        for t in vals.iter().take(3) {
            parse_finite(t).map_err(|m| format!("normal {m}"))?;
            out.push(' ');
            out.push_str(t);
        }
        push_line(&mut self.scan.normalized, &out);
        self.scan.normals += 1;
        Ok(())
    }

    /// `f v1 v2 v3 ...`: every vertex checked against the elements seen so far, and all of one
    /// form (each names a texture coordinate, or none does; the same for normals): a face that
    /// mixes them would leave the mesh's texture coordinates or normals without one per vertex,
    /// and all of them generated.
    fn face<'a>(
        &mut self,
        toks: impl Iterator<Item = &'a str>,
        rest: &str,
    ) -> Result<[bool; 2], String> {
        let mut count = 0usize;
        let mut first: Option<(&str, [bool; 2])> = None;
        for t in toks {
            let form = check_face_vertex(
                t,
                [self.scan.positions, self.scan.texcoords, self.scan.normals],
            )?;
            match first {
                None => first = Some((t, form)),
                Some((f, first_form)) if first_form != form => {
                    let (what, has) = if first_form[0] == form[0] {
                        ("a normal", first_form[1])
                    } else {
                        ("a texture coordinate", first_form[0])
                    };
                    let (with, without) = if has { (f, t) } else { (t, f) };
                    return Err(format!(
                        "face mixes vertex forms: `{with}` names {what} and `{without}` does not \
                         (every vertex of a face has the same form: v, v/vt, v//vn or v/vt/vn)"
                    ));
                }
                Some(_) => {}
            }
            count += 1;
        }
        if count < 3 {
            return Err(format!("face has {count} vertices, need at least 3"));
        }
        if count > 3 {
            self.polygons += 1;
        }
        self.scan.faces += 1;
        push_line(&mut self.scan.normalized, &format!("f {rest}"));
        Ok(first.map_or([false; 2], |(_, form)| form))
    }

    /// A face whose form differs from the first face of its mesh: tobj then has texture
    /// coordinates or normals for some of the mesh's vertices only, and all of them are
    /// generated (`from_triangles`); warned once per mesh, naming both lines.
    fn note_face_form(&mut self, path: &Path, lineno: usize, form: [bool; 2]) {
        let Some((first, line, warned)) = &mut self.mesh_form else {
            self.mesh_form = Some((form, lineno, false));
            return;
        };
        if *first == form || *warned {
            return;
        }
        *warned = true;
        let (what, has) = if first[0] == form[0] {
            ("normals", form[1])
        } else {
            ("texture coordinates", form[0])
        };
        let (with, without) = if has {
            (lineno, *line)
        } else {
            (*line, lineno)
        };
        warn(
            &mut self.scan.warnings,
            format!(
                "{}:{with}: this face names {what} and the face at line {without} of the same \
                 mesh does not: the mesh's {what} are generated for all of it",
                path.display()
            ),
        );
    }

    /// `usemtl name` or `mtllib file...`; `key` alone is skipped with a warning.
    fn material_statement(&mut self, key: &str, rest: &str, lineno: usize) {
        if rest.is_empty() {
            self.unnamed.push((key.to_string(), lineno));
            if key == "usemtl" {
                // The faces after it take the default material, as after a name that
                // no MTL defines.
                push_line(&mut self.scan.normalized, &format!("usemtl {NO_MATERIAL}"));
            }
            return;
        }
        if key == "usemtl" {
            self.scan.usemtls.push((rest.to_string(), lineno));
        } else {
            self.scan.mtllibs.push(lineno);
        }
        push_line(&mut self.scan.normalized, &format!("{key} {rest}"));
    }

    /// The scan, with the warnings about what was decoded lossily, skipped, triangulated or
    /// ignored.
    fn finish(self, path: &Path, text: &LossyLines) -> Scan {
        let Prescan {
            mut scan,
            first_skipped,
            polygons,
            colors,
            unsupported,
            first_unsupported,
            unnamed,
            mesh_form: _,
        } = self;
        let p = path.display();
        let mut notes = Vec::new();
        notes.extend(text.warning(path));
        for (key, line) in unnamed {
            let what = if key == "usemtl" {
                "the faces after it use the default material"
            } else {
                "ignored"
            };
            notes.push(format!("{p}:{line}: `{key}` without a name; {what}"));
        }
        if let Some(line) = first_skipped {
            notes.push(format!(
                "{p}:{line}: skipped {} point (p) and {} line (l) elements (only faces are rendered)",
                scan.points, scan.lines
            ));
        }
        if polygons > 0 {
            notes.push(format!(
                "{p}: triangulated {polygons} polygons with more than 3 vertices"
            ));
        }
        if colors > 0 {
            notes.push(format!("{p}: ignored vertex colours on {colors} vertices"));
        }
        if let Some((k, line)) = first_unsupported {
            notes.push(format!(
                "{p}:{line}: ignored {unsupported} unsupported statements (first: `{k}`)"
            ));
        }
        for msg in notes {
            warn(&mut scan.warnings, msg);
        }
        scan
    }
}

/// Drops an inline comment from an element line (`v`, `vt`, `vn`, `f`, `l`, `p`); other
/// statements keep their `#`, since names and file paths may contain one.
fn strip_inline_comment(line: &str) -> &str {
    if matches!(
        line.split_whitespace().next(),
        Some("v" | "vt" | "vn" | "f" | "l" | "p")
    ) {
        line.split_once('#')
            .map_or(line, |(before, _)| before)
            .trim_end()
    } else {
        line
    }
}

fn push_line(out: &mut String, line: &str) {
    out.push_str(line);
    out.push('\n');
}

fn parse_finite(t: &str) -> Result<f32, String> {
    let v: f32 = t.parse().map_err(|_| format!("has invalid number `{t}`"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("has non-finite value `{t}`"))
    }
}

const INDEX_KINDS: [(&str, &str); 3] = [
    ("face index", "positions"),
    ("texture coordinate index", "texture coordinates"),
    ("normal index", "normals"),
];

/// Checks one `v`, `v/vt`, `v//vn` or `v/vt/vn` face vertex against the
/// element counts seen so far, and says whether it names a texture coordinate and a normal.
/// Never allocates based on an index value.
fn check_face_vertex(tok: &str, counts: [usize; 3]) -> Result<[bool; 2], String> {
    let mut form = [false; 2];
    for (k, part) in tok.split('/').enumerate() {
        let (Some((kind, plural)), Some(&count)) = (INDEX_KINDS.get(k), counts.get(k)) else {
            return Err(format!("face vertex `{tok}` has more than 3 components"));
        };
        if part.is_empty() {
            if k == 0 {
                return Err(format!("face vertex `{tok}` has no position index"));
            }
            continue;
        }
        if let Some(named) = k.checked_sub(1).and_then(|i| form.get_mut(i)) {
            *named = true;
        }
        let count_u = count as u64;
        match part.parse::<i64>() {
            Ok(0) => return Err(format!("{kind} 0 is invalid (OBJ indices start at 1)")),
            Ok(x) if x > 0 && x.unsigned_abs() > count_u => {
                return Err(format!("{kind} {x} out of range ({count} {plural})"))
            }
            Ok(x) if x < 0 && x.unsigned_abs() > count_u => {
                return Err(format!(
                    "relative {kind} {x} out of range ({count} {plural})"
                ))
            }
            Ok(_) => {}
            Err(_) => {
                let digits = part.strip_prefix(['-', '+']).unwrap_or(part);
                if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
                    return Err(format!("{kind} {part} out of range ({count} {plural})"));
                }
                return Err(format!("invalid {kind} `{part}`"));
            }
        }
    }
    Ok(form)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_vertex_checks() {
        let c = [3, 2, 1];
        assert_eq!(check_face_vertex("1", c), Ok([false, false]));
        assert_eq!(check_face_vertex("-3/-2/-1", c), Ok([true, true]));
        assert_eq!(check_face_vertex("3//1", c), Ok([false, true]));
        assert_eq!(check_face_vertex("3/1/", c), Ok([true, false]));
        assert!(check_face_vertex("4", c).is_err_and(|e| e.contains("4 out of range")));
        assert!(check_face_vertex("1/3", c).is_err_and(|e| e.contains("texture coordinate")));
        assert!(check_face_vertex("1/1/2", c).is_err_and(|e| e.contains("normal index 2")));
        assert!(check_face_vertex("1/1/1/1", c).is_err_and(|e| e.contains("more than 3")));
        assert!(check_face_vertex("/1", c).is_err_and(|e| e.contains("no position")));
        assert!(check_face_vertex("x", c).is_err_and(|e| e.contains("invalid face index")));
        assert!(check_face_vertex("-9223372036854775808", c).is_err());
    }
}
