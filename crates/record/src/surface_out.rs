//! A textured drape surface in the files people open: a binary glTF 2.0 (`drape.glb`: Blender,
//! three.js, any glTF viewer) and a rerun recording (Mesh3D with texture coordinates and the albedo
//! texture).

use crate::rerun;
use crate::{Staged, write_atomic};
use anyhow::Result;
use drapelab_core::surface::SurfaceMesh;
use image::RgbImage;
use serde_json::json;
use std::io::Write;
use std::path::Path;

/// A textured drape surface to write: the mesh, a texture coordinate per vertex, the texture image
/// and a name for the node and mesh.
#[derive(Clone, Copy)]
pub struct TexturedSurface<'a> {
    /// The evaluated surface.
    pub mesh: &'a SurfaceMesh,
    /// Texture coordinates (s, t) of its vertices.
    pub st: &'a [[f64; 2]],
    /// The texture.
    pub texture: &'a RgbImage,
    /// Name of the node and mesh (the scene's).
    pub name: &'a str,
}

/// drapelab's +Z-up metres to glTF's +Y-up metres: (x, y, z) → (x, z, −y), a rotation.
fn y_up(p: &nalgebra::Vector3<f64>) -> [f32; 3] {
    [p.x as f32, p.z as f32, -p.y as f32]
}

/// The texture as PNG bytes.
fn png_bytes(texture: &RgbImage) -> Result<Vec<u8>> {
    let mut png = Vec::new();
    texture.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)?;
    Ok(png)
}

/// Appends `bytes` to `bin` (4-byte aligned) and returns its (offset, length).
fn push_view(bin: &mut Vec<u8>, bytes: &[u8]) -> (usize, usize) {
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let off = bin.len();
    bin.extend_from_slice(bytes);
    (off, bytes.len())
}

/// The bytes of a binary glTF 2.0 of `surface`, its texture embedded as PNG: positions and normals +Y up in metres, one double-sided material
/// (metallic 0, roughness 1), the texture repeating.
pub fn glb_bytes(surface: &TexturedSurface<'_>) -> Result<Vec<u8>> {
    let TexturedSurface {
        mesh,
        st,
        texture,
        name,
    } = *surface;
    anyhow::ensure!(
        st.len() == mesh.positions.len(),
        "one texture coordinate per vertex"
    );
    let a = attributes(mesh, st);
    let png = png_bytes(texture)?;
    let mut bin = Vec::new();
    let views: Vec<(usize, usize)> = [&a.pos, &a.nor, &a.tex, &a.idx, &png]
        .iter()
        .map(|b| push_view(&mut bin, b))
        .collect();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let n = mesh.positions.len();
    const ARRAY_BUFFER: u32 = 34962;
    const ELEMENT_ARRAY_BUFFER: u32 = 34963;
    const FLOAT: u32 = 5126;
    const UNSIGNED_INT: u32 = 5125;
    let view = |k: usize, target: Option<u32>| {
        let mut v = json!({"buffer": 0, "byteOffset": views[k].0, "byteLength": views[k].1});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        v
    };
    let doc = json!({
        "asset": {"version": "2.0", "generator": format!("drapelab {}", drapelab_core::VERSION),
                  "extras": {"units": "m", "up": "+Y (drapelab's +Z)"}},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": name}],
        "meshes": [{"name": name, "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
            "indices": 3, "material": 0, "mode": 4}]}],
        "materials": [{"name": "fabric", "doubleSided": true, "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0}, "metallicFactor": 0.0, "roughnessFactor": 1.0}}],
        "textures": [{"sampler": 0, "source": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}],
        "images": [{"bufferView": 4, "mimeType": "image/png"}],
        "accessors": [
            {"bufferView": 0, "componentType": FLOAT, "count": n, "type": "VEC3", "min": a.lo, "max": a.hi},
            {"bufferView": 1, "componentType": FLOAT, "count": n, "type": "VEC3"},
            {"bufferView": 2, "componentType": FLOAT, "count": n, "type": "VEC2"},
            {"bufferView": 3, "componentType": UNSIGNED_INT, "count": mesh.triangles.len() * 3, "type": "SCALAR"},
        ],
        "bufferViews": [view(0, Some(ARRAY_BUFFER)), view(1, Some(ARRAY_BUFFER)), view(2, Some(ARRAY_BUFFER)),
                        view(3, Some(ELEMENT_ARRAY_BUFFER)), view(4, None)],
        "buffers": [{"byteLength": bin.len()}],
    });
    glb_container(&serde_json::to_vec(&doc)?, &bin)
}

/// The vertex attributes of a glTF mesh as little-endian bytes (positions and unit normals turned
/// y-up, texture coordinates, triangle indices) with the positions' bounds.
struct Attributes {
    pos: Vec<u8>,
    nor: Vec<u8>,
    tex: Vec<u8>,
    idx: Vec<u8>,
    lo: [f32; 3],
    hi: [f32; 3],
}

/// The [`Attributes`] of `mesh` with texture coordinates `st`.
fn attributes(mesh: &SurfaceMesh, st: &[[f64; 2]]) -> Attributes {
    let f32s = |v: &mut Vec<u8>, xs: &[f32]| {
        xs.iter()
            .for_each(|x| v.extend_from_slice(&x.to_le_bytes()))
    };
    let (mut pos, mut nor, mut tex, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        let q = y_up(p);
        for c in 0..3 {
            lo[c] = lo[c].min(q[c]);
            hi[c] = hi[c].max(q[c]);
        }
        f32s(&mut pos, &q);
        let m = y_up(n);
        let len = m
            .iter()
            .map(|c| c * c)
            .sum::<f32>()
            .sqrt()
            .max(f32::MIN_POSITIVE);
        f32s(&mut nor, &m.map(|c| c / len));
    }
    for s in st {
        f32s(&mut tex, &[s[0] as f32, s[1] as f32]);
    }
    for t in &mesh.triangles {
        t.iter()
            .for_each(|k| idx.extend_from_slice(&k.to_le_bytes()));
    }
    Attributes {
        pos,
        nor,
        tex,
        idx,
        lo,
        hi,
    }
}

/// The binary glTF container (glTF 2.0 §4.4): a 12-byte header, the JSON chunk padded with spaces
/// and the binary chunk (already padded to 4 bytes).
fn glb_container(json: &[u8], bin: &[u8]) -> Result<Vec<u8>> {
    let mut js = json.to_vec();
    while !js.len().is_multiple_of(4) {
        js.push(b' ');
    }
    let total = 12 + 8 + js.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(js.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&js);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    Ok(out)
}

/// Writes [`glb_bytes`] to `out`, atomically.
pub fn write_glb(out: &Path, surface: &TexturedSurface<'_>) -> Result<()> {
    let bytes = glb_bytes(surface)?;
    write_atomic(out, |f| {
        f.write_all(&bytes)?;
        Ok(())
    })?;
    Ok(())
}

/// Writes a rerun recording of the textured surface at `surface/<name>` (Z up, metres), atomically.
pub fn write_surface_rrd(out: &Path, surface: &TexturedSurface<'_>) -> Result<()> {
    let TexturedSurface {
        mesh, st, texture, ..
    } = *surface;
    let staged = Staged::new(out)?;
    let rec = rerun::RecordingStreamBuilder::new("drapelab_surface").save(staged.path())?;
    rec.log_static("/", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
    let f3 = |p: &nalgebra::Vector3<f64>| [p.x as f32, p.y as f32, p.z as f32];
    let format = rerun::components::ImageFormat::rgb8([texture.width(), texture.height()]);
    rec.log_static(
        format!("surface/{}", surface.name),
        &rerun::Mesh3D::new(mesh.positions.iter().map(f3))
            .with_vertex_normals(mesh.normals.iter().map(f3))
            .with_vertex_texcoords(st.iter().map(|s| [s[0] as f32, s[1] as f32]))
            .with_triangle_indices(mesh.triangles.iter().copied())
            .with_albedo_texture(format, texture.as_raw().clone()),
    )?;
    rec.flush_blocking()?;
    drop(rec);
    staged.commit()?;
    Ok(())
}
