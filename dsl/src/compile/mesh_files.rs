//! Decoding mesh asset files into triangles: glTF 2.0 through the `gltf` crate's document types
//! (the bytes of every accessor read here, each range checked first, so no input can panic),
//! and OBJ through `tobj`; with the limits every asset is held to (its bytes through [`Budget`],
//! its declared vertices and triangles before any is read).
//!
//! Axis convention (both formats, as glTF defines it and OBJ exporters write by default): the
//! asset is in metres with y up. Its x is the piece's x, its -z the piece's y, its y the
//! height above the ground; so an asset seen from above (looking down -y) shows the floor plan
//! as the piece draws it, and `clayc export` writes it back as it was read.

use std::borrow::Cow;
use std::collections::HashMap;
use std::io::Cursor;

use base64::Engine;
use glam::{DMat4, DVec2, DVec3};
use gltf::mesh::Mode;

use super::imports::Loader;
use super::imports::resolve;
use super::limits::MAX_COORDINATE;
use crate::compiled::{ProxyShape, Rgba};

/// Largest mesh asset file, with its external buffers (16 MiB).
pub const MAX_MESH_BYTES: usize = 16 << 20;
/// Most bytes all mesh assets of one grammar may have together (64 MiB).
pub const MAX_MESH_TOTAL_BYTES: usize = 64 << 20;
/// Most vertices one mesh asset may have (after its nodes are instanced).
pub const MAX_MESH_VERTICES: usize = 200_000;
/// Most triangles one mesh asset may have (after its nodes are instanced).
pub const MAX_MESH_TRIANGLES: usize = 200_000;

/// The triangles of one colour of a decoded asset, in piece coordinates.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct AssetPart {
    /// The material's base colour (sRGB), when the asset gives one.
    pub fill: Option<Rgba>,
    pub shape: ProxyShape,
}

/// The loader with the byte limits: every file an asset reads (itself, its `.bin` buffers,
/// its `.mtl` materials) counts towards [`MAX_MESH_BYTES`] and [`MAX_MESH_TOTAL_BYTES`].
pub(super) struct Budget<'a> {
    total: &'a mut usize,
    loader: &'a dyn Loader,
}

impl<'a> Budget<'a> {
    pub fn new(total: &'a mut usize, loader: &'a dyn Loader) -> Self {
        Self { total, loader }
    }

    pub fn load(&mut self, path: &str) -> Result<Vec<u8>, Problem> {
        let bytes = self
            .loader
            .load(path)
            .map_err(|e| Problem::Io(path.to_string(), e))?;
        if bytes.len() > MAX_MESH_BYTES {
            return Err(Problem::TooLarge(format!(
                "`{path}` has more than {} MiB",
                MAX_MESH_BYTES >> 20
            )));
        }
        *self.total += bytes.len();
        if *self.total > MAX_MESH_TOTAL_BYTES {
            return Err(Problem::TooLarge(format!(
                "the grammar's mesh assets have more than {} MiB together",
                MAX_MESH_TOTAL_BYTES >> 20
            )));
        }
        Ok(bytes)
    }
}

/// Most levels of nodes in a glTF scene (a deeper hierarchy is taken for a cycle).
const MAX_NODE_DEPTH: usize = 64;
/// Most node visits while placing a glTF scene's meshes.
const MAX_NODE_VISITS: usize = 100_000;

/// Why an asset cannot be used.
#[derive(Debug)]
pub(super) enum Problem {
    /// A file (the asset or one it refers to) that cannot be read.
    Io(String, std::io::Error),
    /// An extension Clay does not read (`None`: no extension).
    Format(Option<String>),
    Malformed(String),
    TooLarge(String),
}

fn malformed(why: impl Into<String>) -> Problem {
    Problem::Malformed(why.into())
}

/// The triangles of an asset being decoded, one group per colour, within the limits.
#[derive(Default)]
struct Collect {
    groups: Vec<(Option<Rgba>, Group)>,
    vertices: usize,
    triangles: usize,
}

#[derive(Default)]
struct Group {
    points: Vec<DVec2>,
    heights: Vec<f64>,
    triangles: Vec<[u32; 3]>,
}

impl Collect {
    /// Counts what an asset declares before any of it is read: a file cannot make Clay
    /// allocate more than the limits allow.
    fn declare(&mut self, vertices: usize, triangles: usize) -> Result<(), Problem> {
        self.vertices = self.vertices.saturating_add(vertices);
        self.triangles = self.triangles.saturating_add(triangles);
        if self.vertices > MAX_MESH_VERTICES {
            return Err(Problem::TooLarge(format!(
                "it has {} vertices, more than {MAX_MESH_VERTICES}",
                self.vertices
            )));
        }
        if self.triangles > MAX_MESH_TRIANGLES {
            return Err(Problem::TooLarge(format!(
                "it has {} triangles, more than {MAX_MESH_TRIANGLES}",
                self.triangles
            )));
        }
        Ok(())
    }

    /// Adds triangles over `positions` (asset coordinates, y up) in colour `fill`. Indices must
    /// be in range; triangles without area are left out, and so are vertices no triangle uses.
    fn add(
        &mut self,
        fill: Option<Rgba>,
        positions: &[DVec3],
        triangles: impl Iterator<Item = [u32; 3]>,
    ) -> Result<(), Problem> {
        if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
            return Err(malformed(format!("a vertex position is not finite ({p})")));
        }
        // Within the coordinates a grammar may have, so that every later computation stays
        // finite: a vertex beyond f32's range, which a node's scale can put it at, would be
        // exported and drawn at infinity.
        if let Some(p) = positions
            .iter()
            .find(|p| p.abs().max_element() > MAX_COORDINATE)
        {
            return Err(malformed(format!(
                "a vertex is at {p}, more than {MAX_COORDINATE:e} m from the origin along an axis \
                 (the limit of every coordinate)"
            )));
        }
        let at = match self.groups.iter().position(|(f, _)| *f == fill) {
            Some(i) => i,
            None => {
                self.groups.push((fill, Group::default()));
                self.groups.len() - 1
            }
        };
        let group = &mut self.groups[at].1;
        let mut index: HashMap<u32, u32> = HashMap::new();
        for t in triangles {
            let Some(c) = t
                .iter()
                .map(|&i| positions.get(i as usize))
                .collect::<Option<Vec<_>>>()
            else {
                return Err(malformed(format!(
                    "a triangle refers to vertex {}, of {}",
                    t.iter().max().copied().unwrap_or(0),
                    positions.len()
                )));
            };
            if (*c[1] - *c[0]).cross(*c[2] - *c[0]).length_squared() <= 0.0 {
                continue;
            }
            let t = t.map(|i| {
                *index.entry(i).or_insert_with(|| {
                    let p = positions[i as usize];
                    group.points.push(DVec2::new(p.x, -p.z));
                    group.heights.push(p.y);
                    (group.points.len() - 1) as u32
                })
            });
            group.triangles.push(t);
        }
        Ok(())
    }

    fn finish(self) -> Result<Vec<AssetPart>, Problem> {
        let parts: Vec<AssetPart> = self
            .groups
            .into_iter()
            .filter(|(_, g)| !g.triangles.is_empty())
            .map(|(fill, g)| AssetPart {
                fill,
                shape: ProxyShape::Mesh {
                    points: g.points,
                    heights: g.heights,
                    triangles: g.triangles,
                },
            })
            .collect();
        if parts.is_empty() {
            return Err(malformed("it has no triangles"));
        }
        Ok(parts)
    }
}

/// A glTF 2.0 asset (`.glb`, or `.gltf` with data-URI or `.bin` buffers): the triangles of
/// every mesh its scene places, in its nodes' transforms, coloured by base colour factor.
pub(super) fn gltf(
    bytes: &[u8],
    target: &str,
    budget: &mut Budget,
) -> Result<Vec<AssetPart>, Problem> {
    check_glb_header(bytes)?;
    let text = !bytes.starts_with(b"glTF");
    if text && bytes.iter().find(|b| !b.is_ascii_whitespace()) != Some(&b'{') {
        return Err(malformed(
            "it is neither binary glTF (which starts with `glTF`) nor glTF JSON (which starts with `{`)",
        ));
    }
    let doc = validated(bytes)?;
    let buffers = buffers(&doc, target, budget)?;
    let placed = placements(&doc)?;
    let mut c = Collect::default();
    for (mesh, _) in &placed {
        for p in mesh.primitives() {
            let (v, t) = declared(&p);
            c.declare(v, t)?;
        }
    }
    for (mesh, world) in &placed {
        for p in mesh.primitives() {
            primitive(&p, *world, &buffers, &mut c)?;
        }
    }
    c.finish()
}

/// The document, validated by the `gltf` crate, whose validation itself trusts one reference
/// (a primitive's `POSITION` accessor): that one is checked first.
fn validated(bytes: &[u8]) -> Result<gltf::Gltf, Problem> {
    let raw =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| malformed(format!("{e}")))?;
    let json = raw.document.as_json();
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for p in &mesh.primitives {
            if let Some(a) = p.attributes.values().find(|a| a.value() >= accessors) {
                return Err(malformed(format!(
                    "mesh {m} refers to accessor {}, of {accessors}",
                    a.value()
                )));
            }
        }
    }
    let document = gltf::Document::from_json(raw.document.into_json())
        .map_err(|e| malformed(format!("{e}")))?;
    Ok(gltf::Gltf {
        document,
        blob: raw.blob,
    })
}

/// A GLB's header must hold its own length: the `gltf` crate assumes it does.
fn check_glb_header(bytes: &[u8]) -> Result<(), Problem> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let length = bytes
        .get(8..12)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    match length {
        Some(n) if n >= 20 && n <= bytes.len() => Ok(()),
        Some(n) => Err(malformed(format!(
            "the GLB header declares {n} bytes, but the file has {} (truncated?)",
            bytes.len()
        ))),
        None => Err(malformed("the GLB file is truncated inside its header")),
    }
}

/// Every buffer's bytes, at least as many as it declares.
fn buffers(doc: &gltf::Gltf, target: &str, budget: &mut Budget) -> Result<Vec<Vec<u8>>, Problem> {
    let mut out = Vec::new();
    for b in doc.buffers() {
        let data = match b.source() {
            gltf::buffer::Source::Bin => doc.blob.clone().ok_or_else(|| {
                malformed(format!(
                    "buffer {} is the GLB's binary chunk, which is missing",
                    b.index()
                ))
            })?,
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => data_uri(uri)
                .ok_or_else(|| {
                    malformed(format!("buffer {}'s data URI is not base64", b.index()))
                })?,
            gltf::buffer::Source::Uri(uri) => budget.load(&resolve(target, uri))?,
        };
        if data.len() < b.length() {
            return Err(malformed(format!(
                "buffer {} has {} bytes but declares {}",
                b.index(),
                data.len(),
                b.length()
            )));
        }
        out.push(data);
    }
    Ok(out)
}

fn data_uri(uri: &str) -> Option<Vec<u8>> {
    let (head, data) = uri.split_once(',')?;
    if !head.ends_with(";base64") {
        return None;
    }
    base64::engine::general_purpose::STANDARD.decode(data).ok()
}

/// Every mesh the scene places, with its node's world transform (the default scene, else the
/// first; a file without scenes places each mesh once, untransformed).
fn placements(doc: &gltf::Gltf) -> Result<Vec<(gltf::Mesh<'_>, DMat4)>, Problem> {
    let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) else {
        return Ok(doc.meshes().map(|m| (m, DMat4::IDENTITY)).collect());
    };
    let mut out = Vec::new();
    let mut stack: Vec<(gltf::Node, DMat4, usize)> =
        scene.nodes().map(|n| (n, DMat4::IDENTITY, 1)).collect();
    let mut visits = 0usize;
    while let Some((node, parent, depth)) = stack.pop() {
        visits += 1;
        if depth > MAX_NODE_DEPTH || visits > MAX_NODE_VISITS {
            return Err(malformed(format!(
                "its node hierarchy is deeper than {MAX_NODE_DEPTH} or has more than \
                 {MAX_NODE_VISITS} placements (a cycle?)"
            )));
        }
        let local = node.transform().matrix().map(|c| c.map(f64::from));
        let world = parent * DMat4::from_cols_array_2d(&local);
        if let Some(m) = node.mesh() {
            out.push((m, world));
        }
        stack.extend(node.children().map(|c| (c, world, depth + 1)));
    }
    Ok(out)
}

/// The vertices and triangles a primitive declares (0 for points and lines).
fn declared(p: &gltf::Primitive) -> (usize, usize) {
    let vertices = p.get(&gltf::Semantic::Positions).map_or(0, |a| a.count());
    let corners = p.indices().map_or(vertices, |a| a.count());
    let triangles = match p.mode() {
        Mode::Triangles => corners / 3,
        Mode::TriangleStrip | Mode::TriangleFan => corners.saturating_sub(2),
        _ => 0,
    };
    (vertices, triangles)
}

fn primitive(
    p: &gltf::Primitive,
    world: DMat4,
    buffers: &[Vec<u8>],
    c: &mut Collect,
) -> Result<(), Problem> {
    if !matches!(
        p.mode(),
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    ) {
        return Ok(()); // points and lines have no surface
    }
    let Some(pos) = p.get(&gltf::Semantic::Positions) else {
        return Err(malformed("a primitive has no POSITION attribute"));
    };
    if pos.data_type() != gltf::accessor::DataType::F32
        || pos.dimensions() != gltf::accessor::Dimensions::Vec3
    {
        return Err(malformed(
            "its positions are not 32-bit float VEC3 (quantized meshes are not read)",
        ));
    }
    let positions: Vec<DVec3> = elements(&pos, buffers)?
        .map(|b| {
            let f = |k: usize| f32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]) as f64;
            world.transform_point3(DVec3::new(f(0), f(4), f(8)))
        })
        .collect();
    let corners: Vec<u32> = match p.indices() {
        None => (0..positions.len() as u32).collect(),
        Some(a) => {
            let read: fn(&[u8]) -> u32 = match (a.data_type(), a.dimensions()) {
                (gltf::accessor::DataType::U8, gltf::accessor::Dimensions::Scalar) => {
                    |b| b[0] as u32
                }
                (gltf::accessor::DataType::U16, gltf::accessor::Dimensions::Scalar) => {
                    |b| u16::from_le_bytes([b[0], b[1]]) as u32
                }
                (gltf::accessor::DataType::U32, gltf::accessor::Dimensions::Scalar) => {
                    |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])
                }
                _ => return Err(malformed("its indices are not unsigned integers")),
            };
            elements(&a, buffers)?.map(read).collect()
        }
    };
    let flip = world.determinant() < 0.0;
    let triangles =
        triangles_of(p.mode(), &corners).map(|[a, b, c]| if flip { [a, c, b] } else { [a, b, c] });
    let fill = p.material().index().map(|_| {
        let [r, g, b, a] = p.material().pbr_metallic_roughness().base_color_factor();
        Rgba([
            linear_to_srgb(r),
            linear_to_srgb(g),
            linear_to_srgb(b),
            unit_to_byte(a),
        ])
    });
    c.add(fill, &positions, triangles)
}

/// The triangles of a primitive's corner list, counter-clockwise as glTF defines each mode.
fn triangles_of(mode: Mode, corners: &[u32]) -> Box<dyn Iterator<Item = [u32; 3]> + '_> {
    match mode {
        Mode::TriangleStrip => Box::new(corners.windows(3).enumerate().map(|(i, w)| {
            if i % 2 == 0 {
                [w[0], w[1], w[2]]
            } else {
                [w[1], w[0], w[2]]
            }
        })),
        Mode::TriangleFan => Box::new(
            corners
                .windows(2)
                .skip(1)
                .map(move |w| [corners[0], w[0], w[1]]),
        ),
        _ => Box::new(corners.chunks_exact(3).map(|t| [t[0], t[1], t[2]])),
    }
}

/// The bytes of each element of an accessor, every range checked against its buffer view and
/// buffer first (the `gltf` crate's own reader trusts the declared sizes).
fn elements<'b>(
    a: &gltf::Accessor,
    buffers: &'b [Vec<u8>],
) -> Result<impl Iterator<Item = &'b [u8]>, Problem> {
    let which = a.index();
    if a.sparse().is_some() {
        return Err(malformed(format!(
            "accessor {which} is sparse, which Clay does not read"
        )));
    }
    let Some(view) = a.view() else {
        return Err(malformed(format!("accessor {which} has no buffer view")));
    };
    let size = a.size();
    let stride = view.stride().unwrap_or(size).max(size);
    let count = a.count();
    let data = buffers
        .get(view.buffer().index())
        .map_or(&[][..], |b| &b[..]);
    let span = view
        .offset()
        .checked_add(view.length())
        .and_then(|end| data.get(view.offset()..end));
    let need = count
        .checked_sub(1)
        .map(|n| n.checked_mul(stride).and_then(|x| x.checked_add(size)))
        .unwrap_or(Some(0))
        .and_then(|n| n.checked_add(a.offset()));
    let bytes = match (span, need) {
        (Some(view_bytes), Some(need)) if need <= view_bytes.len() => view_bytes,
        _ => {
            return Err(malformed(format!(
                "accessor {which} declares {count} elements, more than its buffer holds"
            )));
        }
    };
    let start = a.offset();
    Ok((0..count).map(move |i| &bytes[start + i * stride..start + i * stride + size]))
}

fn unit_to_byte(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// The sRGB byte of a linear channel (glTF's colour factors are linear).
fn linear_to_srgb(c: f32) -> u8 {
    let c = if c.is_finite() {
        c.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let s = if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    unit_to_byte(s)
}

/// An OBJ asset: every face (triangulated), coloured by its material's diffuse colour when a
/// `.mtl` beside it gives one (a missing `.mtl` only loses the colours).
pub(super) fn obj(
    bytes: &[u8],
    target: &str,
    budget: &mut Budget,
) -> Result<Vec<AssetPart>, Problem> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let mut mtl_bytes: HashMap<String, Vec<u8>> = HashMap::new();
    // tobj asks for materials through a `Fn`; read them first so the budget sees them, and
    // check them, since tobj panics on some malformed lines.
    for line in String::from_utf8_lossy(bytes).lines() {
        if let Some(name) = line.trim().strip_prefix("mtllib ") {
            let path = resolve(target, name.trim());
            match budget.load(&path) {
                Ok(b) => {
                    check_mtl(&b, &path)?;
                    mtl_bytes.insert(name.trim().to_string(), b);
                }
                // A missing `.mtl` only loses the colours.
                Err(Problem::Io(_, e)) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(problem) => return Err(problem),
            }
        }
    }
    let bytes = positions_only(bytes);
    let (models, materials) = tobj::load_obj_buf(&mut Cursor::new(&bytes[..]), &options, |p| {
        let name = p.to_string_lossy();
        match mtl_bytes.get(name.as_ref()) {
            Some(b) => tobj::load_mtl_buf(&mut Cursor::new(b)),
            None => Err(tobj::LoadError::OpenFileFailed),
        }
    })
    .map_err(|e| malformed(format!("not valid OBJ: {e}")))?;
    let materials = materials.unwrap_or_default();
    let mut c = Collect::default();
    for m in &models {
        c.declare(m.mesh.positions.len() / 3, m.mesh.indices.len() / 3)?;
    }
    for m in &models {
        let positions: Vec<DVec3> = m
            .mesh
            .positions
            .chunks_exact(3)
            .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
            .collect();
        let fill = m
            .mesh
            .material_id
            .and_then(|i| materials.get(i))
            .and_then(|mat| mat.diffuse)
            .map(|[r, g, b]| Rgba([unit_to_byte(r), unit_to_byte(g), unit_to_byte(b), 255]));
        let triangles = m.mesh.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]);
        c.add(fill, &positions, triangles)?;
    }
    c.finish()
}

/// The OBJ with every vertex of a face or line reduced to its position index (`f 1/2/3` is
/// `f 1`): Clay reads no texture coordinates or normals, and tobj's arithmetic on their
/// indices overflows, a panic where overflow is checked, on a relative one such as
/// `f 1//-3` or a huge one. Lines are split into words as tobj splits them; other lines, and
/// lines that are not UTF-8, stay as they are.
fn positions_only(bytes: &[u8]) -> Cow<'_, [u8]> {
    if !bytes
        .split(|&b| b == b'\n')
        .any(|line| face(line).is_some())
    {
        return Cow::Borrowed(bytes);
    }
    let mut out = Vec::with_capacity(bytes.len());
    for (k, line) in bytes.split(|&b| b == b'\n').enumerate() {
        if k > 0 {
            out.push(b'\n');
        }
        let Some((keyword, words)) = face(line) else {
            out.extend_from_slice(line);
            continue;
        };
        out.extend_from_slice(keyword.as_bytes());
        for w in words {
            // `/2/3` names no position: `0` is as out of range as that.
            let position = w.split('/').next().filter(|p| !p.is_empty());
            out.push(b' ');
            out.extend_from_slice(position.unwrap_or("0").as_bytes());
        }
    }
    Cow::Owned(out)
}

/// The keyword (`f` or `l`) and the vertices of a face or line with a `/` in it.
fn face(line: &[u8]) -> Option<(&str, std::str::SplitWhitespace<'_>)> {
    let text = std::str::from_utf8(line).ok()?;
    let mut words = text.split_whitespace();
    let keyword = words.next().filter(|k| matches!(*k, "f" | "l"))?;
    text.contains('/').then_some((keyword, words))
}

/// A `.mtl` file's colour lines (`Ka`, `Kd`, `Ks`, `Ke`) must each have three numbers: tobj
/// panics on fewer. The first line that does not is reported with its line and column.
fn check_mtl(bytes: &[u8], path: &str) -> Result<(), Problem> {
    let text = String::from_utf8_lossy(bytes);
    for (n, line) in text.split('\n').enumerate() {
        let mut words = line.split_whitespace();
        let Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) = words.next() else {
            continue;
        };
        let numbers = words.take(3).filter(|w| w.parse::<f32>().is_ok()).count();
        if numbers < 3 {
            let column = line[..line.find(key).unwrap_or(0)].chars().count() + 1;
            return Err(malformed(format!(
                "its material file `{path}`, line {}, column {column}: `{key}` must be \
                 followed by three numbers (red, green, blue)",
                n + 1
            )));
        }
    }
    Ok(())
}
