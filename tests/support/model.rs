//! A procedural glTF 2.0 test model: a torus with all five metallic–roughness texture
//! slots filled (base colour checker, roughness ramp and metal cells, dimpled normal map,
//! grooves in the occlusion, glowing dots), a node transform, written as a `.glb`.
//! `display/assets/torus.glb` is this output (checked by a test).

use std::f32::consts::TAU;

const SIZE: u32 = 128;
const CELLS: u32 = 8;

fn png(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
    let mut img = image::RgbImage::new(w, h);
    for y in 0..h {
        for x in 0..w {
            img.put_pixel(x, y, image::Rgb(f(x, y)));
        }
    }
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// Position in the cell grid: cell index and offset from the cell centre in [−½, ½].
fn cell(x: u32, y: u32) -> (u32, u32, f32, f32) {
    let c = SIZE / CELLS;
    let (cx, cy) = (x / c, y / c);
    let fx = ((x % c) as f32 + 0.5) / c as f32 - 0.5;
    let fy = ((y % c) as f32 + 0.5) / c as f32 - 0.5;
    (cx, cy, fx, fy)
}

fn textures() -> [Vec<u8>; 5] {
    let base = png(SIZE, SIZE, |x, y| {
        let (cx, cy, _, _) = cell(x, y);
        if (cx + cy) % 2 == 0 { [235, 220, 190] } else { [30, 110, 120] }
    });
    let mr = png(SIZE, SIZE, |x, y| {
        let (cx, cy, _, _) = cell(x, y);
        let rough = (20 + 215 * x / (SIZE - 1)) as u8;
        let metal = if (cx + cy) % 2 == 1 { 255 } else { 0 };
        [0, rough, metal]
    });
    let normal = png(SIZE, SIZE, |x, y| {
        let (_, _, fx, fy) = cell(x, y);
        let r2 = fx * fx + fy * fy;
        // A spherical dimple of radius 0.4 cell in each cell.
        let (nx, ny) = if r2 < 0.16 { (fx * 1.5, fy * 1.5) } else { (0.0, 0.0) };
        let nz = (1.0 - nx * nx - ny * ny).max(0.0).sqrt();
        [nx, ny, nz].map(|v| ((v * 0.5 + 0.5) * 255.0).round() as u8)
    });
    let occlusion = png(SIZE, SIZE, |x, y| {
        let (_, _, fx, fy) = cell(x, y);
        let edge = fx.abs().max(fy.abs());
        let v = if edge > 0.42 { 110 } else { 255 };
        [v, v, v]
    });
    let emissive = png(SIZE, SIZE, |x, y| {
        let (cx, cy, fx, fy) = cell(x, y);
        if (cx + 2 * cy) % 5 == 0 && fx * fx + fy * fy < 0.02 { [255, 140, 40] } else { [0, 0, 0] }
    });
    [base, mr, normal, occlusion, emissive]
}

/// The torus: positions, normals, tangents, uvs and CCW-outward triangles.
#[allow(clippy::type_complexity)]
fn torus() -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[f32; 4]>, Vec<[f32; 2]>, Vec<u32>) {
    let (nu, nv) = (64u32, 32u32);
    let (big, small) = (1.0f32, 0.4f32);
    let (mut p, mut n, mut t, mut uv) = (vec![], vec![], vec![], vec![]);
    for j in 0..=nv {
        for i in 0..=nu {
            let (su, cu) = (TAU * i as f32 / nu as f32).sin_cos();
            let (sv, cv) = (TAU * j as f32 / nv as f32).sin_cos();
            p.push([(big + small * cv) * cu, small * sv, (big + small * cv) * su]);
            let normal = [cv * cu, sv, cv * su];
            n.push(normal);
            // Tangent along +s (increasing u), bitangent along +t (increasing v).
            let tan = [-su, 0.0, cu];
            let bit = [-sv * cu, cv, -sv * su];
            let cross = [normal[1] * tan[2] - normal[2] * tan[1], normal[2] * tan[0] - normal[0] * tan[2], normal[0] * tan[1] - normal[1] * tan[0]];
            let w = if cross[0] * bit[0] + cross[1] * bit[1] + cross[2] * bit[2] < 0.0 { -1.0 } else { 1.0 };
            t.push([tan[0], tan[1], tan[2], w]);
            uv.push([3.0 * i as f32 / nu as f32, j as f32 / nv as f32]);
        }
    }
    let mut idx = Vec::new();
    let at = |i: u32, j: u32| j * (nu + 1) + i;
    for j in 0..nv {
        for i in 0..nu {
            for tri in [[at(i, j), at(i + 1, j), at(i + 1, j + 1)], [at(i, j), at(i + 1, j + 1), at(i, j + 1)]] {
                // Orient counter-clockwise seen from outside.
                let [a, b, c] = tri.map(|k| p[k as usize]);
                let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                let f = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
                let nn = n[tri[0] as usize];
                if f[0] * nn[0] + f[1] * nn[1] + f[2] * nn[2] < 0.0 {
                    idx.extend([tri[0], tri[2], tri[1]]);
                } else {
                    idx.extend(tri);
                }
            }
        }
    }
    (p, n, t, uv, idx)
}

/// The `.glb` bytes of the test model.
pub fn sample_glb() -> Vec<u8> {
    sample_glb_with(None)
}

/// The `.glb` bytes of the test model, its material carrying `extensions` (listed in
/// `extensionsUsed`) where given.
pub fn sample_glb_with(extensions: Option<serde_json::Value>) -> Vec<u8> {
    let (p, n, t, uv, idx) = torus();
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut push = |bytes: &[u8], bin: &mut Vec<u8>| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(serde_json::json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend_from_slice(bytes);
        views.len() - 1
    };
    let f32s = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let vp = push(&f32s(&p.concat()), &mut bin);
    let vn = push(&f32s(&n.concat()), &mut bin);
    let vt = push(&f32s(&t.concat()), &mut bin);
    let vu = push(&f32s(&uv.concat()), &mut bin);
    let vi = push(&idx.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>(), &mut bin);
    let images: Vec<usize> = textures().iter().map(|png| push(png, &mut bin)).collect();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let (lo, hi) = p.iter().fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), q| {
        ([lo[0].min(q[0]), lo[1].min(q[1]), lo[2].min(q[2])], [hi[0].max(q[0]), hi[1].max(q[1]), hi[2].max(q[2])])
    });
    let count = p.len();
    let mut json = serde_json::json!({
        "asset": {"version": "2.0", "generator": "splitsum tests/support/model.rs"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        // Tilted a quarter turn about x and scaled: node transforms must be applied.
        "nodes": [{"mesh": 0, "rotation": [0.5, 0.0, 0.0, 0.866_025_4], "scale": [2.0, 2.0, 2.0]}],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TANGENT": 2, "TEXCOORD_0": 3},
            "indices": 4, "material": 0
        }]}],
        "materials": [{
            "name": "checker",
            "pbrMetallicRoughness": {
                "baseColorFactor": [1.0, 1.0, 1.0, 1.0], "baseColorTexture": {"index": 0},
                "metallicFactor": 1.0, "roughnessFactor": 1.0, "metallicRoughnessTexture": {"index": 1}
            },
            "normalTexture": {"index": 2, "scale": 1.0},
            "occlusionTexture": {"index": 3, "strength": 1.0},
            "emissiveTexture": {"index": 4}, "emissiveFactor": [4.0, 4.0, 4.0]
        }],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}],
        "textures": (0..5).map(|k| serde_json::json!({"source": k, "sampler": 0})).collect::<Vec<_>>(),
        "images": images.iter().map(|&v| serde_json::json!({"bufferView": v, "mimeType": "image/png"})).collect::<Vec<_>>(),
        "accessors": [
            {"bufferView": vp, "componentType": 5126, "count": count, "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": vn, "componentType": 5126, "count": count, "type": "VEC3"},
            {"bufferView": vt, "componentType": 5126, "count": count, "type": "VEC4"},
            {"bufferView": vu, "componentType": 5126, "count": count, "type": "VEC2"},
            {"bufferView": vi, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}]
    });
    if let Some(ext) = extensions {
        json["extensionsUsed"] =
            serde_json::Value::Array(ext.as_object().expect("extensions by name").keys().map(|k| serde_json::Value::String(k.clone())).collect());
        json["materials"][0]["extensions"] = ext;
    }
    glb(&json, &bin)
}

/// A binary glTF: the JSON chunk (padded with spaces) and the BIN chunk (`bin`, already
/// padded to 4 bytes), after the 12-byte header.
pub fn glb(json: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut text = serde_json::to_vec(json).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut glb = Vec::new();
    glb.extend_from_slice(b"glTF");
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&((12 + 8 + text.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend_from_slice(&(text.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(&text);
    glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"BIN\0");
    glb.extend_from_slice(bin);
    glb
}

/// A GLB holding one Draco-compressed primitive (`KHR_draco_mesh_compression`): `stream`
/// in buffer view 0, attributes by Draco unique id, `count` points and `faces` triangles.
pub fn draco_glb(stream: &[u8], ids: [(&str, u32, &str); 3], count: usize, faces: usize) -> Vec<u8> {
    let mut attributes = serde_json::Map::new();
    let mut draco = serde_json::Map::new();
    let mut accessors = Vec::new();
    for (k, (name, id, kind)) in ids.iter().enumerate() {
        attributes.insert(name.to_string(), serde_json::json!(k));
        draco.insert(name.to_string(), serde_json::json!(id));
        accessors.push(serde_json::json!({"componentType": 5126, "count": count, "type": kind}));
    }
    accessors.push(serde_json::json!({"componentType": 5125, "count": 3 * faces, "type": "SCALAR"}));
    let mut bin = stream.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_draco_mesh_compression"],
        "extensionsRequired": ["KHR_draco_mesh_compression"],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": stream.len()}],
        "accessors": accessors,
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 3, "mode": 4,
            "extensions": {"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": draco}}}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    glb(&json, &bin)
}

/// The embedded torus's first primitive (positions, normals, UVs; no node transform)
/// compressed with `draco-core`'s encoder at `speed` (0: EdgeBreaker, which reorders
/// vertices and faces; 10: sequential), with 14-bit positions, 10-bit normals and 12-bit
/// UVs, as a `KHR_draco_mesh_compression` GLB.
pub fn draco_torus_glb(speed: i32) -> Vec<u8> {
    use draco_core::{DataType, EncoderBuffer, EncoderOptions, FaceIndex, GeometryAttributeType, Mesh, MeshEncoder, PointAttribute};
    let (doc, buffers, _) = gltf::import_slice(splitsum_display::model::EMBEDDED_SAMPLE).unwrap();
    let prim = doc.meshes().next().unwrap().primitives().next().unwrap();
    let r = prim.reader(|b| Some(&buffers[b.index()].0[..]));
    let positions: Vec<[f32; 3]> = r.read_positions().unwrap().collect();
    let normals: Vec<[f32; 3]> = r.read_normals().unwrap().collect();
    let uvs: Vec<[f32; 2]> = r.read_tex_coords(0).unwrap().into_f32().collect();
    let indices: Vec<u32> = r.read_indices().unwrap().into_u32().collect();
    let n = positions.len();
    let attribute = |kind, comps: u8, values: Vec<f32>| {
        let mut a = PointAttribute::new();
        a.init(kind, comps, DataType::Float32, false, n);
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        a.buffer_mut().write(0, &bytes);
        a
    };
    let mut mesh = Mesh::new();
    mesh.set_num_points(n);
    let ids = [
        mesh.add_attribute(attribute(GeometryAttributeType::Position, 3, positions.concat())),
        mesh.add_attribute(attribute(GeometryAttributeType::Normal, 3, normals.concat())),
        mesh.add_attribute(attribute(GeometryAttributeType::TexCoord, 2, uvs.concat())),
    ];
    let faces = indices.len() / 3;
    mesh.set_num_faces(faces);
    for f in 0..faces {
        mesh.set_face(FaceIndex(f as u32), [indices[3 * f].into(), indices[3 * f + 1].into(), indices[3 * f + 2].into()]);
    }
    let mut options = EncoderOptions::new();
    options.set_global_int("encoding_speed", speed);
    options.set_global_int("decoding_speed", speed);
    options.set_attribute_int(0, "quantization_bits", 14);
    options.set_attribute_int(1, "quantization_bits", 10);
    options.set_attribute_int(2, "quantization_bits", 12);
    let mut encoder = MeshEncoder::new();
    encoder.set_mesh(mesh.clone());
    let mut stream = EncoderBuffer::new();
    encoder.encode(&options, &mut stream).unwrap();
    let uid = |k: usize| mesh.attribute(ids[k]).unique_id();
    draco_glb(stream.data(), [("POSITION", uid(0), "VEC3"), ("NORMAL", uid(1), "VEC3"), ("TEXCOORD_0", uid(2), "VEC2")], n, faces)
}
