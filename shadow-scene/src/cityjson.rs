//! CityJSON city models (versions 1.0 to 2.0) as meshes: every surface of
//! every city object, one group per object named by its id.
//!
//! What is read, for each city object (buildings, their parts, bridges,
//! terrain, trees, ...):
//!
//! - its geometries of the highest level of detail it has (`"lod"`, a
//!   string such as `"2.2"` or a number; a file that gives an object both
//!   an LoD 1 block and an LoD 2 model would otherwise cast each shadow
//!   twice);
//! - `MultiSurface`, `CompositeSurface`, `Solid` (every shell, cavities
//!   too: they still cast shadows), `MultiSolid`, `CompositeSolid`, and
//!   `GeometryInstance` (a shared template placed by its 4 × 4 matrix and
//!   reference point);
//! - `MultiPoint` and `MultiLineString` have no area and are skipped.
//!
//! A surface without holes is one face, its ring as given (faces need not
//! be convex: the importers triangulate them exactly). A surface with
//! holes (a wall with its windows) is triangulated by earcut in the
//! surface's best-fitting plane, the triangles turning as its outer ring
//! does. Vertices are scaled and translated by the file's `"transform"`.
//! Errors name the place in the file as a JSON pointer
//! (`city.json: /CityObjects/b12/geometry/0/boundaries/0/2/0: vertex 9999
//! out of range (0..=1233)`).

use std::path::Path;

use glam::DVec3;
use serde_json::{Map, Value};

use crate::{Face, Mesh, SceneError};

/// Reads a CityJSON file ([`parse_cityjson`]).
pub fn read_cityjson(path: &Path) -> Result<Mesh, SceneError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: shown.clone(),
        source,
    })?;
    parse_cityjson(&text, &shown)
}

/// A CityJSON document as a mesh (see the module's documentation): one
/// group per city object with a surface, named by its id, in the order of
/// the ids; the positions are the file's vertices, transformed, then the
/// templates' placed copies.
///
/// ```
/// let city = r#"{"type": "CityJSON", "version": "2.0",
///   "transform": {"scale": [0.5, 0.5, 0.5], "translate": [100, 200, 0]},
///   "vertices": [[0,0,0], [2,0,0], [2,2,0], [0,2,0]],
///   "CityObjects": {"yard": {"type": "LandUse",
///     "geometry": [{"type": "MultiSurface", "lod": "1", "boundaries": [[[0,1,2,3]]]}]}}}"#;
/// let mesh = shadow_scene::parse_cityjson(city, "block.city.json").unwrap();
/// assert_eq!(mesh.groups, ["yard"]);
/// assert_eq!(mesh.positions[2], glam::DVec3::new(101.0, 201.0, 0.0));
///
/// let bad = city.replace("[0,1,2,3]", "[0,1,2,7]");
/// let e = shadow_scene::parse_cityjson(&bad, "block.city.json").unwrap_err();
/// assert_eq!(
///     e.to_string(),
///     "block.city.json: /CityObjects/yard/geometry/0/boundaries/0/0/3: vertex 7 out of range (0..=3)"
/// );
/// ```
pub fn parse_cityjson(text: &str, path_for_messages: &str) -> Result<Mesh, SceneError> {
    // (JSON has no byte-order mark, but some tools write one)
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let fail = |message: String| SceneError::Parse {
        path: path_for_messages.to_string(),
        line: 0,
        message,
    };
    let root: Value = serde_json::from_str(text).map_err(|e| SceneError::Parse {
        path: path_for_messages.to_string(),
        line: e.line(),
        message: format!("not JSON: {e}"),
    })?;
    let mut reader = Reader::new(&root).map_err(fail)?;
    let objects = object(&root, "CityObjects", "").map_err(fail)?;
    // in the ids' order, whatever the JSON map keeps
    let mut ids: Vec<&String> = objects.keys().collect();
    ids.sort_unstable();
    for id in ids {
        let city_object = &objects[id];
        let at = format!("/CityObjects/{}", pointer_token(id));
        reader.city_object(id, city_object, &at).map_err(fail)?;
    }
    if reader.mesh.faces.is_empty() {
        return Err(fail("no city object has a surface".into()));
    }
    Ok(reader.mesh)
}

/// The mesh being made, and what the geometries refer to.
struct Reader<'a> {
    mesh: Mesh,
    /// How many vertices the file has (the positions' first ones).
    vertices: usize,
    /// The templates and their vertices (real coordinates), if any.
    templates: Option<(&'a [Value], Vec<DVec3>)>,
}

impl<'a> Reader<'a> {
    /// The document's vertices, transformed, and its templates.
    fn new(root: &'a Value) -> Result<Reader<'a>, String> {
        match root.get("type").and_then(Value::as_str) {
            Some("CityJSON") => {}
            Some(other) => return Err(format!("/type: `{other}`, not a CityJSON document")),
            None => return Err("/type: missing: not a CityJSON document".into()),
        }
        let (scale, translate) = match root.get("transform") {
            None | Some(Value::Null) => (DVec3::ONE, DVec3::ZERO),
            Some(t) => (
                point(t.get("scale"), "/transform/scale")?,
                point(t.get("translate"), "/transform/translate")?,
            ),
        };
        let positions = array(root.get("vertices"), "/vertices")?
            .iter()
            .enumerate()
            .map(|(i, v)| {
                // (the path for an error is made only for one)
                let p = match quick_point(v) {
                    Some(p) => p,
                    None => point(Some(v), &format!("/vertices/{i}"))?,
                };
                Ok(p * scale + translate)
            })
            .collect::<Result<Vec<DVec3>, String>>()?;
        let templates = match root.get("geometry-templates") {
            None | Some(Value::Null) => None,
            Some(t) => {
                let at = "/geometry-templates";
                let list = array(t.get("templates"), &format!("{at}/templates"))?;
                let vertices = array(
                    t.get("vertices-templates"),
                    &format!("{at}/vertices-templates"),
                )?
                .iter()
                .enumerate()
                .map(|(i, v)| point(Some(v), &format!("{at}/vertices-templates/{i}")))
                .collect::<Result<Vec<DVec3>, String>>()?;
                Some((list.as_slice(), vertices))
            }
        };
        let mesh = Mesh {
            positions,
            faces: Vec::new(),
            groups: Vec::new(),
        };
        let vertices = mesh.positions.len();
        Ok(Reader {
            mesh,
            vertices,
            templates,
        })
    }

    /// The surfaces of one city object's most detailed geometries, in a
    /// group named `id`.
    fn city_object(&mut self, id: &str, city_object: &Value, at: &str) -> Result<(), String> {
        let Some(geometries) = city_object.get("geometry") else {
            return Ok(());
        };
        let geometries = array(Some(geometries), &format!("{at}/geometry"))?;
        let lods = geometries
            .iter()
            .enumerate()
            .map(|(i, g)| lod(g, &format!("{at}/geometry/{i}")))
            .collect::<Result<Vec<f64>, String>>()?;
        let Some(top) = lods.iter().copied().reduce(f64::max) else {
            return Ok(());
        };
        let faces_before = self.mesh.faces.len();
        self.mesh.groups.push(id.to_string());
        let group = (self.mesh.groups.len() - 1) as u32;
        for (i, g) in geometries.iter().enumerate() {
            if lods[i] == top {
                self.geometry(g, group, &format!("{at}/geometry/{i}"))?;
            }
        }
        if self.mesh.faces.len() == faces_before {
            self.mesh.groups.pop(); // points and lines only
        }
        Ok(())
    }

    /// One geometry's surfaces as faces of `group`.
    fn geometry(&mut self, g: &Value, group: u32, at: &str) -> Result<(), String> {
        let kind = g
            .get("type")
            .and_then(Value::as_str)
            .ok_or_else(|| format!("{at}/type: missing"))?;
        if kind == "GeometryInstance" {
            return self.instance(g, group, at);
        }
        let Some(depth) = depth(kind, at)? else {
            return Ok(());
        };
        let mut surfaces = Vec::new();
        collect_surfaces(
            g.get("boundaries"),
            depth,
            &format!("{at}/boundaries"),
            &mut surfaces,
        )?;
        for (surface, place) in surfaces {
            let rings = rings(surface, &place, self.vertices)?;
            self.surface(&rings, group);
        }
        Ok(())
    }

    /// A template's surfaces placed by an instance's matrix at its
    /// reference point.
    fn instance(&mut self, g: &Value, group: u32, at: &str) -> Result<(), String> {
        let Some((templates, vertices)) = &self.templates else {
            return Err(format!(
                "{at}: a GeometryInstance in a file without geometry-templates"
            ));
        };
        let t = g
            .get("template")
            .and_then(Value::as_u64)
            .ok_or_else(|| format!("{at}/template: missing or not an index"))?;
        let template = templates.get(t as usize).ok_or_else(|| {
            format!(
                "{at}/template: template {t} out of range (0..{})",
                templates.len()
            )
        })?;
        let reference = array(g.get("boundaries"), &format!("{at}/boundaries"))?;
        let [r] = reference.as_slice() else {
            return Err(format!("{at}/boundaries: one reference point expected"));
        };
        let r = index(r, &format!("{at}/boundaries/0"), self.vertices)?;
        let m = array(
            g.get("transformationMatrix"),
            &format!("{at}/transformationMatrix"),
        )?;
        let m: Vec<f64> = m.iter().filter_map(Value::as_f64).collect();
        if m.len() != 16 || m.iter().any(|x| !x.is_finite()) {
            return Err(format!(
                "{at}/transformationMatrix: 16 finite numbers expected"
            ));
        }
        let origin = self.mesh.positions[r as usize];
        let put = |p: DVec3| {
            let row =
                |k: usize| m[4 * k] * p.x + m[4 * k + 1] * p.y + m[4 * k + 2] * p.z + m[4 * k + 3];
            origin + DVec3::new(row(0), row(1), row(2))
        };
        let tat = format!("/geometry-templates/templates/{t}");
        let kind = template.get("type").and_then(Value::as_str).unwrap_or("");
        let Some(depth) = depth(kind, &tat)? else {
            return Ok(());
        };
        let placed: Vec<DVec3> = vertices.iter().map(|&p| put(p)).collect();
        let count = vertices.len();
        let mut surfaces = Vec::new();
        collect_surfaces(
            template.get("boundaries"),
            depth,
            &format!("{tat}/boundaries"),
            &mut surfaces,
        )?;
        // the placed copy's vertices follow the positions so far
        let base = self.mesh.positions.len() as u32;
        self.mesh.positions.extend(placed);
        for (surface, place) in surfaces {
            let mut rings = rings(surface, &place, count)?;
            rings.iter_mut().flatten().for_each(|v| *v += base);
            self.surface(&rings, group);
        }
        Ok(())
    }

    /// One surface (outer ring, then holes) as faces.
    fn surface(&mut self, rings: &[Vec<u32>], group: u32) {
        let face = |vertices: Vec<u32>| Face {
            vertices,
            line: 0,
            group,
        };
        if let [outer] = rings {
            self.mesh.faces.push(face(outer.clone()));
            return;
        }
        let corners: Vec<u32> = rings.concat();
        let points: Vec<[f64; 3]> = corners
            .iter()
            .map(|&v| self.mesh.positions[v as usize].to_array())
            .collect();
        let lens: Vec<usize> = rings.iter().map(Vec::len).collect();
        // (an outer ring with no area: nothing to cast)
        for t in crate::triangulate_rings(&points, &lens) {
            self.mesh.faces.push(face(t.map(|i| corners[i]).to_vec()));
        }
    }
}

/// How deep a geometry type's boundaries nest above its surfaces (1: a
/// list of surfaces; 2: of shells; 3: of solids); `None` for points and
/// lines.
fn depth(kind: &str, at: &str) -> Result<Option<usize>, String> {
    Ok(Some(match kind {
        "MultiSurface" | "CompositeSurface" => 1,
        "Solid" => 2,
        "MultiSolid" | "CompositeSolid" => 3,
        "MultiPoint" | "MultiLineString" => return Ok(None),
        other => return Err(format!("{at}/type: unknown geometry type `{other}`")),
    }))
}

/// A geometry's level of detail as a number (`"2.2"` or `2`; none is 0).
fn lod(g: &Value, at: &str) -> Result<f64, String> {
    match g.get("lod") {
        None | Some(Value::Null) => Ok(0.0),
        Some(Value::Number(n)) => n.as_f64().ok_or_else(|| format!("{at}/lod: not a number")),
        Some(Value::String(s)) => s
            .parse::<f64>()
            .map_err(|_| format!("{at}/lod: `{s}` is not a level of detail")),
        Some(_) => Err(format!("{at}/lod: not a level of detail")),
    }
}

/// The surfaces of a boundary array nested `depth` levels above them
/// ([`depth`]), with their places.
fn collect_surfaces<'v>(
    b: Option<&'v Value>,
    depth: usize,
    at: &str,
    out: &mut Vec<(&'v Value, String)>,
) -> Result<(), String> {
    for (i, item) in array(b, at)?.iter().enumerate() {
        let at = format!("{at}/{i}");
        if depth == 1 {
            out.push((item, at));
        } else {
            collect_surfaces(Some(item), depth - 1, &at, out)?;
        }
    }
    Ok(())
}

/// A surface's rings of vertex indices below `count`.
fn rings(surface: &Value, at: &str, count: usize) -> Result<Vec<Vec<u32>>, String> {
    let rings = array(Some(surface), at)?;
    if rings.is_empty() {
        return Err(format!("{at}: a surface with no ring"));
    }
    rings
        .iter()
        .enumerate()
        .map(|(j, ring)| {
            // a ring of three indices or more, each in range, as it is
            // (the path for an error is made only for one: a path a
            // vertex was most of a city's reading)
            if let Value::Array(r) = ring
                && r.len() >= 3
                && let Some(quick) = r.iter().map(|v| quick_index(v, count)).collect()
            {
                return Ok(quick);
            }
            let at = format!("{at}/{j}");
            let ring = array(Some(ring), &at)?;
            if ring.len() < 3 {
                return Err(format!("{at}: a ring of {} vertices", ring.len()));
            }
            ring.iter()
                .enumerate()
                .map(|(k, v)| index(v, &format!("{at}/{k}"), count))
                .collect()
        })
        .collect()
}

/// [`index`] where `v` is a vertex index below `count`, else `None` (the
/// check alone, with no path for an error's message).
fn quick_index(v: &Value, count: usize) -> Option<u32> {
    v.as_u64()
        .filter(|&i| (i as usize) < count)
        .map(|i| i as u32)
}

/// [`point`] where `v` is three finite numbers, else `None` (the check
/// alone, with no path for an error's message).
fn quick_point(v: &Value) -> Option<DVec3> {
    match v {
        Value::Array(l) if l.len() == 3 => {
            let (x, y, z) = (l[0].as_f64()?, l[1].as_f64()?, l[2].as_f64()?);
            let p = DVec3::new(x, y, z);
            p.is_finite().then_some(p)
        }
        _ => None,
    }
}

/// A vertex index below `count`.
fn index(v: &Value, at: &str, count: usize) -> Result<u32, String> {
    if let Some(i) = quick_index(v, count) {
        return Ok(i);
    }
    match v.as_u64() {
        Some(i) if count == 0 => Err(format!("{at}: vertex {i}, but the file has no vertices")),
        Some(i) => Err(format!("{at}: vertex {i} out of range (0..={})", count - 1)),
        None => Err(format!("{at}: `{v}` is not a vertex index")),
    }
}

/// Three finite numbers.
fn point(v: Option<&Value>, at: &str) -> Result<DVec3, String> {
    if let Some(p) = v.and_then(quick_point) {
        return Ok(p);
    }
    array(v, at)?;
    Err(format!("{at}: three finite numbers expected"))
}

fn array<'v>(v: Option<&'v Value>, at: &str) -> Result<&'v Vec<Value>, String> {
    match v {
        Some(Value::Array(a)) => Ok(a),
        Some(_) => Err(format!("{at}: an array expected")),
        None => Err(format!("{at}: missing")),
    }
}

fn object<'v>(root: &'v Value, key: &str, at: &str) -> Result<&'v Map<String, Value>, String> {
    match root.get(key) {
        Some(Value::Object(m)) => Ok(m),
        Some(_) => Err(format!("{at}/{key}: an object expected")),
        None => Err(format!("{at}/{key}: missing")),
    }
}

/// An object key as a JSON pointer's token (RFC 6901: `~` and `/`
/// escaped).
fn pointer_token(key: &str) -> String {
    key.replace('~', "~0").replace('/', "~1")
}

#[cfg(test)]
mod tests;
