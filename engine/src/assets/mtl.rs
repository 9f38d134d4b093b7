//! Small MTL parser.
//!
//! `tobj`'s own MTL parser is not used: it panics on short colour lines such
//! as `Kd 1 0` (an `unwrap` in its `parse_float3`), reports errors without
//! line numbers and keeps texture options such as `-bm 0.5` in the file
//! name. This parser reports errors with
//! line numbers, strips texture options, accepts `norm`, `map_Bump`/`map_bump`
//! and `bump` for normal maps plus the `map_roughness`/`map_metallic`/
//! `map_clearcoat` extension keys (and the common `map_Pr`/`map_Pm` aliases),
//! and turns unknown keys into warnings.

use std::path::{Path, PathBuf};

use super::error::AssetError;
use super::text::LossyLines;
use super::texture::ColorSpace;

/// Which [`super::MaterialMaps`] slot a texture statement fills.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(super) enum MapSlot {
    BaseColor,
    Normal,
    Specular,
    Roughness,
    Metallic,
    Clearcoat,
}

impl MapSlot {
    pub(super) fn color_space(self) -> ColorSpace {
        match self {
            MapSlot::BaseColor => ColorSpace::Srgb,
            _ => ColorSpace::Linear,
        }
    }
}

/// A texture statement: slot, MTL key as written, resolved path, MTL line.
#[derive(Clone, Debug)]
pub(super) struct MapRef {
    pub slot: MapSlot,
    pub key: String,
    pub path: PathBuf,
    pub line: usize,
}

/// One `newmtl` block.
#[derive(Clone, Debug, Default)]
pub(super) struct ParsedMaterial {
    pub name: String,
    pub diffuse: Option<[f32; 3]>,
    pub specular: Option<[f32; 3]>,
    pub shininess: Option<f32>,
    pub maps: Vec<MapRef>,
}

/// One parsed MTL file.
#[derive(Clone, Debug)]
pub(super) struct ParsedMtl {
    pub path: PathBuf,
    pub materials: Vec<ParsedMaterial>,
    pub warnings: Vec<String>,
}

/// Standard or common keys that are understood but not used by the renderer.
const IGNORED_KEYS: &[&str] = &[
    "ka",
    "ke",
    "ni",
    "d",
    "tr",
    "tf",
    "illum",
    "sharpness",
    "pr",
    "pm",
    "ps",
    "pc",
    "pcr",
    "aniso",
    "anisor",
    "map_ka",
    "map_d",
    "map_ns",
    "map_ke",
    "map_ps",
    "map_aat",
    "disp",
    "decal",
    "refl",
];

/// Reads and parses `path`. `obj`/`obj_line` name the referencing `mtllib`.
pub(super) fn parse_mtl_file(
    path: &Path,
    obj: &Path,
    obj_line: Option<usize>,
) -> Result<ParsedMtl, AssetError> {
    let bytes = std::fs::read(path).map_err(|source| AssetError::MissingMtl {
        path: path.to_path_buf(),
        obj: obj.to_path_buf(),
        line: obj_line,
        source,
    })?;
    parse_mtl_bytes(path, &bytes)
}

/// Parses MTL source; texture paths are resolved against `path`'s directory.
pub(super) fn parse_mtl_bytes(path: &Path, bytes: &[u8]) -> Result<ParsedMtl, AssetError> {
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut materials = Vec::new();
    let (bytes, encoding) = super::text::utf8_bytes(path, bytes);
    let mut warnings: Vec<String> = encoding.into_iter().collect();
    let mut current: Option<ParsedMaterial> = None;
    // Each material name with the line that first defined it.
    let mut defined: Vec<(String, usize)> = Vec::new();
    let mut text = LossyLines::default();
    // Logged at debug level only: callers report the returned list (see `obj::warn`).
    let mut warn = |msg: String| {
        log::debug!("{msg}");
        warnings.push(msg);
    };

    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let lineno = i + 1;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let decoded = text.decode(lineno, raw);
        let line = decoded.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let (key, rest) = match line.split_once(char::is_whitespace) {
            Some((k, r)) => (k, r.trim()),
            None => (line, ""),
        };
        let lkey = key.to_ascii_lowercase();
        if lkey == "newmtl" {
            if let Some(done) = current.take() {
                materials.push(done);
            }
            if rest.is_empty() {
                // No `usemtl` can name it: its block is read and dropped (as a nameless
                // `usemtl`, whose faces get the default material, only warns).
                warn(format!(
                    "{}:{lineno}: `newmtl` without a name; its block is ignored",
                    path.display()
                ));
                current = Some(ParsedMaterial::default());
                continue;
            }
            match defined.iter().find(|(name, _)| name == rest) {
                Some((_, first)) => warn(format!(
                    "{}:{lineno}: `newmtl {rest}` again (first at line {first}): two materials \
                     of one name, which a `usemtl {rest}` cannot tell apart; rename one",
                    path.display()
                )),
                None => defined.push((rest.to_string(), lineno)),
            }
            current = Some(ParsedMaterial {
                name: rest.to_string(),
                ..Default::default()
            });
            continue;
        }
        let Some(mat) = current.as_mut() else {
            warn(format!(
                "{}:{lineno}: `{key}` before any `newmtl` ignored",
                path.display()
            ));
            continue;
        };
        let slot = match lkey.as_str() {
            "kd" | "ks" => {
                let Some(c) = parse_color(path, lineno, key, rest)? else {
                    warn(format!(
                        "{}:{lineno}: unsupported colour form `{line}` ignored",
                        path.display()
                    ));
                    continue;
                };
                if lkey == "kd" {
                    mat.diffuse = Some(c);
                } else {
                    mat.specular = Some(c);
                }
                continue;
            }
            "ns" => {
                mat.shininess = Some(parse_scalar(path, lineno, key, rest)?);
                continue;
            }
            "map_kd" => MapSlot::BaseColor,
            "norm" | "map_bump" | "bump" => MapSlot::Normal,
            "map_ks" => MapSlot::Specular,
            "map_roughness" | "map_pr" => MapSlot::Roughness,
            "map_metallic" | "map_pm" => MapSlot::Metallic,
            "map_clearcoat" => MapSlot::Clearcoat,
            k if IGNORED_KEYS.contains(&k) => {
                log::debug!("{}:{lineno}: `{key}` not used", path.display());
                continue;
            }
            _ => {
                warn(format!(
                    "{}:{lineno}: unknown MTL key `{key}` ignored",
                    path.display()
                ));
                continue;
            }
        };
        let (file, unknown_opts) = parse_map_args(rest);
        for opt in unknown_opts {
            warn(format!(
                "{}:{lineno}: unknown texture option `{opt}` ignored",
                path.display()
            ));
        }
        let file = file.ok_or_else(|| {
            AssetError::parse(path, lineno, format!("`{key}` without a file name"))
        })?;
        let file = if cfg!(windows) {
            file.to_string()
        } else {
            file.replace('\\', "/")
        };
        if Path::new(&file).is_absolute() {
            warn(format!(
                "{}:{lineno}: `{key}` names the absolute path `{file}`; it will not resolve on \
                 another machine (give it relative to the MTL file)",
                path.display()
            ));
        }
        let map = MapRef {
            slot,
            key: key.to_string(),
            path: dir.join(file),
            line: lineno,
        };
        // `norm` is the explicit normal-map key; bump spellings do not override it.
        let explicit_norm = lkey == "norm";
        if let Some(existing) = mat.maps.iter_mut().find(|m| m.slot == slot) {
            if slot == MapSlot::Normal
                && !explicit_norm
                && existing.key.eq_ignore_ascii_case("norm")
            {
                continue;
            }
            *existing = map;
        } else {
            mat.maps.push(map);
        }
    }
    if let Some(done) = current.take() {
        materials.push(done);
    }
    // Nameless blocks were read for their syntax only.
    materials.retain(|m| !m.name.is_empty());
    if let Some(warning) = text.warning(path) {
        warn(warning);
    }
    Ok(ParsedMtl {
        path: path.to_path_buf(),
        materials,
        warnings,
    })
}

fn parse_f32(path: &Path, line: usize, key: &str, tok: &str) -> Result<f32, AssetError> {
    let v: f32 = tok
        .parse()
        .map_err(|_| AssetError::parse(path, line, format!("`{key}`: invalid number `{tok}`")))?;
    if !v.is_finite() {
        return Err(AssetError::parse(
            path,
            line,
            format!("`{key}`: non-finite value `{tok}`"),
        ));
    }
    Ok(v)
}

fn parse_scalar(path: &Path, line: usize, key: &str, rest: &str) -> Result<f32, AssetError> {
    let tok = rest
        .split_whitespace()
        .next()
        .ok_or_else(|| AssetError::parse(path, line, format!("`{key}` needs a value")))?;
    parse_f32(path, line, key, tok)
}

/// `Kd r g b` or `Kd r` (grey). `Ok(None)` for `spectral`/`xyz` forms.
fn parse_color(
    path: &Path,
    line: usize,
    key: &str,
    rest: &str,
) -> Result<Option<[f32; 3]>, AssetError> {
    let toks: Vec<&str> = rest.split_whitespace().take(4).collect();
    if matches!(toks.first(), Some(&"spectral") | Some(&"xyz")) {
        return Ok(None);
    }
    match toks.as_slice() {
        [r] => {
            let r = parse_f32(path, line, key, r)?;
            Ok(Some([r, r, r]))
        }
        [r, g, b] => Ok(Some([
            parse_f32(path, line, key, r)?,
            parse_f32(path, line, key, g)?,
            parse_f32(path, line, key, b)?,
        ])),
        _ => Err(AssetError::parse(
            path,
            line,
            format!("`{key}` needs 3 values, found {}", toks.len()),
        )),
    }
}

/// Texture options and how many arguments they take (`None`: 1 to 3 numbers).
const MAP_OPTIONS: &[(&str, Option<usize>)] = &[
    ("-blendu", Some(1)),
    ("-blendv", Some(1)),
    ("-cc", Some(1)),
    ("-clamp", Some(1)),
    ("-imfchan", Some(1)),
    ("-texres", Some(1)),
    ("-bm", Some(1)),
    ("-boost", Some(1)),
    ("-type", Some(1)),
    ("-mm", Some(2)),
    ("-o", None),
    ("-s", None),
    ("-t", None),
];

/// Skips texture options and returns the file name (which may contain
/// spaces; `None` when no file name is left) and the unknown options seen.
fn parse_map_args(rest: &str) -> (Option<&str>, Vec<&str>) {
    let spans = token_spans(rest);
    let mut unknown = Vec::new();
    let mut i = 0;
    while let Some(&(s, e)) = spans.get(i) {
        let tok = rest.get(s..e).unwrap_or("");
        if !tok.starts_with('-') || i + 1 == spans.len() {
            return (rest.get(s..).map(str::trim), unknown);
        }
        i += 1;
        match MAP_OPTIONS
            .iter()
            .find(|(name, _)| tok.eq_ignore_ascii_case(name))
        {
            Some((_, Some(n))) => i += n,
            Some((_, None)) => {
                let mut taken = 0;
                while taken < 3 {
                    let is_num = spans
                        .get(i)
                        .and_then(|&(s, e)| rest.get(s..e))
                        .is_some_and(|t| t.parse::<f32>().is_ok());
                    // Never swallow the last token: it is the file name.
                    if !is_num || i + 1 >= spans.len() {
                        break;
                    }
                    i += 1;
                    taken += 1;
                }
            }
            None => unknown.push(tok),
        }
    }
    (None, unknown)
}

/// Byte ranges of whitespace-separated tokens.
fn token_spans(s: &str) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = None;
    for (i, c) in s.char_indices() {
        match (c.is_whitespace(), start) {
            (true, Some(st)) => {
                spans.push((st, i));
                start = None;
            }
            (false, None) => start = Some(i),
            _ => {}
        }
    }
    if let Some(st) = start {
        spans.push((st, s.len()));
    }
    spans
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_options_are_skipped() {
        assert_eq!(parse_map_args("tex.png"), (Some("tex.png"), vec![]));
        assert_eq!(parse_map_args("-bm 0.5 n.png"), (Some("n.png"), vec![]));
        assert_eq!(
            parse_map_args("-o 0.5 0.5 -s 2 -clamp on my file.png"),
            (Some("my file.png"), vec![])
        );
        assert_eq!(parse_map_args("-o 1 2 3 4.png"), (Some("4.png"), vec![]));
        assert_eq!(parse_map_args("-zz a.png"), (Some("a.png"), vec!["-zz"]));
        assert_eq!(parse_map_args("-bm 0.5"), (None, vec![]));
        assert_eq!(parse_map_args(""), (None, vec![]));
        assert_eq!(parse_map_args("-weird.png"), (Some("-weird.png"), vec![]));
    }

    /// Two `newmtl` of one name warn, naming both lines; distinct names do not.
    #[test]
    fn a_material_named_twice_warns() {
        let src = b"newmtl wood\nKd 0.5\nnewmtl iron\nnewmtl wood\nKd 0.2\n";
        let mtl = parse_mtl_bytes(Path::new("dir/x.mtl"), src).unwrap();
        assert_eq!(mtl.materials.len(), 3);
        assert_eq!(
            mtl.warnings,
            [
                "dir/x.mtl:4: `newmtl wood` again (first at line 1): two materials of one name, \
              which a `usemtl wood` cannot tell apart; rename one"
            ]
        );
    }

    #[test]
    fn bump_does_not_override_norm_and_paths_are_relative() {
        let src = b"newmtl m\nnorm n.png\nbump b.png\nmap_Kd sub\\\\d.png\nKd 0.5\n";
        let mtl = parse_mtl_bytes(Path::new("dir/x.mtl"), src).unwrap();
        let m = mtl.materials[0].clone();
        let normal = m
            .maps
            .iter()
            .find(|x| x.slot == MapSlot::Normal)
            .map(|x| x.path.clone());
        assert_eq!(normal, Some(PathBuf::from("dir/n.png")));
        assert_eq!(m.diffuse, Some([0.5; 3]));
        assert!(mtl.warnings.is_empty(), "{:?}", mtl.warnings);
        // An absolute map path loads, with a warning naming the file and line.
        let src = b"newmtl m\nmap_Kd /textures/wood.png\n";
        let mtl = parse_mtl_bytes(Path::new("dir/x.mtl"), src).unwrap();
        assert_eq!(
            mtl.materials[0].maps[0].path,
            PathBuf::from("/textures/wood.png")
        );
        assert!(
            mtl.warnings
                .iter()
                .any(|w| w.starts_with("dir/x.mtl:2:") && w.contains("absolute path")),
            "{:?}",
            mtl.warnings
        );
    }
}
