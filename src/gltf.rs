//! The motion as a glTF 2.0 file, for Blender, three.js, model viewers: one node per body or
//! frame carrying its shapes as a mesh (boxes, cylinders and spheres as triangles, lines as
//! line primitives), and one animation whose channels move each node along the recorded
//! poses (translation and rotation, sampled at the outputs, linear interpolation).
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # mbs::multibody! { model Swing { dof a = 0.5; body bar { mass = 1.0; inertia = (0.1, 0.01, 0.1); }
//! #   TOG[bar] = Trotz(a) * Tdisp(0, -0.5, 0); shape bar: box(0.05, 1.0, 0.05); gravity(0, -9.81, 0); } }
//! use mbs::Model;
//! let model = Swing::default();
//! let info = model.info();
//! let options = mbs::Options { frames: true, ..mbs::Options::adaptive(2.0, 1e-6) };
//! let (trajectory, _) = mbs::simulate(model, mbs::Scheme::Dopri5, options)?;
//! mbs::gltf::write_gltf("swing.gltf".as_ref(), info, &trajectory)?;
//! # Ok(()) }
//! ```
//!
//! The file is self-contained: its one buffer is a base64 `data:` URI. Lengths are the model's
//! (metres); glTF's up axis is +y, so a model whose up axis is z (see
//! [`Up`](crate::anim::Up)) hangs below a root node turned by −90° about x, and the body
//! nodes keep the model's world coordinates. Animation times are `t − t₀`.

use crate::anim::{ExportError, Frames, Up, palette};
use crate::model::{ModelInfo, ShapeInfo, ShapeKind};
use crate::trajectory::Trajectory;
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};
use serde_json::json;
use std::collections::BTreeMap;
use std::path::Path;

/// Segments around a cylinder and a sphere.
pub const ROUND_SEGMENTS: usize = 24;
/// Rings of a sphere from pole to pole.
pub const SPHERE_RINGS: usize = 12;

/// A shape as polygons in its frame's axes: convex faces, counter-clockwise seen from outside
/// (indices into `positions`), with per-vertex normals, and segments for lines.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tessellation {
    pub positions: Vec<[f64; 3]>,
    /// outward unit normals, one per position (smooth on round surfaces)
    pub normals: Vec<[f64; 3]>,
    pub faces: Vec<Vec<u32>>,
    pub lines: Vec<[u32; 2]>,
}

impl Tessellation {
    /// The faces as triangles (fans), counter-clockwise seen from outside.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        self.faces
            .iter()
            .flat_map(|f| (1..f.len().saturating_sub(1)).map(move |k| [f[0], f[k], f[k + 1]]))
            .collect()
    }
}

fn unit(i: usize) -> [f64; 3] {
    let mut e = [0.0; 3];
    e[i % 3] = 1.0;
    e
}

fn combo(terms: &[(f64, [f64; 3])]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (s, v) in terms {
        for k in 0..3 {
            out[k] += s * v[k];
        }
    }
    out
}

/// Vertices, normals and faces of `shape`, in the axes of its frame.
pub fn tessellate(shape: &ShapeInfo) -> Tessellation {
    let mut t = Tessellation::default();
    let vertex = |t: &mut Tessellation, p: [f64; 3], n: [f64; 3]| -> u32 {
        t.positions.push(p);
        t.normals.push(n);
        (t.positions.len() - 1) as u32
    };
    let tau = std::f64::consts::TAU;
    match shape.kind {
        ShapeKind::Box { size } => {
            let h = size.map(|s| s / 2.0);
            for k in 0..3 {
                for s in [1.0, -1.0] {
                    let n = combo(&[(s, unit(k))]);
                    let (u, v) = if s > 0.0 {
                        ((k + 1) % 3, (k + 2) % 3)
                    } else {
                        ((k + 2) % 3, (k + 1) % 3)
                    };
                    let face = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                        .map(|(a, b)| {
                            let p = combo(&[
                                (s * h[k], unit(k)),
                                (a * h[u], unit(u)),
                                (b * h[v], unit(v)),
                            ]);
                            vertex(&mut t, p, n)
                        })
                        .to_vec();
                    t.faces.push(face);
                }
            }
        }
        ShapeKind::Cylinder {
            radius,
            length,
            axis,
        } => {
            let (a, u, v) = (unit(axis), unit(axis + 1), unit(axis + 2));
            let n = ROUND_SEGMENTS;
            let ring = |j: usize| {
                let th = tau * j as f64 / n as f64;
                combo(&[(th.cos(), u), (th.sin(), v)])
            };
            let side: Vec<[u32; 2]> = (0..n)
                .map(|j| {
                    let d = ring(j);
                    [-0.5, 0.5].map(|s| vertex(&mut t, combo(&[(radius, d), (s * length, a)]), d))
                })
                .collect();
            for j in 0..n {
                let (b0, t0) = (side[j][0], side[j][1]);
                let (b1, t1) = (side[(j + 1) % n][0], side[(j + 1) % n][1]);
                t.faces.push(vec![b0, b1, t1, t0]);
            }
            for s in [1.0, -1.0] {
                let normal = combo(&[(s, a)]);
                let mut cap: Vec<u32> = (0..n)
                    .map(|j| {
                        vertex(
                            &mut t,
                            combo(&[(radius, ring(j)), (s * length / 2.0, a)]),
                            normal,
                        )
                    })
                    .collect();
                if s < 0.0 {
                    cap.reverse();
                }
                t.faces.push(cap);
            }
        }
        ShapeKind::Sphere { radius } => {
            let (n, m) = (ROUND_SEGMENTS, SPHERE_RINGS);
            let mut grid = vec![vec![0u32; n]; m + 1];
            for (i, row) in grid.iter_mut().enumerate() {
                let phi = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * i as f64 / m as f64;
                for (j, idx) in row.iter_mut().enumerate() {
                    let th = tau * j as f64 / n as f64;
                    let d = [phi.cos() * th.cos(), phi.cos() * th.sin(), phi.sin()];
                    *idx = vertex(&mut t, d.map(|c| radius * c), d);
                }
            }
            for i in 0..m {
                for j in 0..n {
                    let jj = (j + 1) % n;
                    let quad = [grid[i][j], grid[i][jj], grid[i + 1][jj], grid[i + 1][j]];
                    // at the poles a ring is one point: keep a triangle
                    let face: Vec<u32> = if i == 0 {
                        vec![quad[0], quad[2], quad[3]]
                    } else if i + 1 == m {
                        vec![quad[0], quad[1], quad[2]]
                    } else {
                        quad.to_vec()
                    };
                    t.faces.push(face);
                }
            }
        }
        ShapeKind::Line { from, to } => {
            let d = combo(&[(1.0, to), (-1.0, from)]);
            let a = vertex(&mut t, from, d);
            let b = vertex(&mut t, to, d);
            t.lines.push([a, b]);
            // a line's ends are already in the frame's axes
            return t;
        }
    }
    let r = &shape.rotation;
    let turn = |p: [f64; 3]| [0, 1, 2].map(|i| r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2]);
    for p in &mut t.positions {
        *p = shape.to_frame(*p);
    }
    for n in &mut t.normals {
        *n = turn(*n);
    }
    t
}

/// Options of [`write_gltf_with`].
#[derive(Clone, Debug, Default)]
pub struct GltfOptions {
    /// which world axis points up (glTF's +y)
    pub up: Up,
}

/// Writes `trajectory` (recorded with `Options::frames = true`) of the model described by
/// `info` as a glTF 2.0 file at `path`.
pub fn write_gltf(
    path: &Path,
    info: &ModelInfo,
    trajectory: &Trajectory,
) -> Result<(), ExportError> {
    write_gltf_with(path, info, trajectory, &GltfOptions::default())
}

/// [`write_gltf`] with options.
pub fn write_gltf_with(
    path: &Path,
    info: &ModelInfo,
    trajectory: &Trajectory,
    options: &GltfOptions,
) -> Result<(), ExportError> {
    let root = document(info, trajectory, options)?;
    let text =
        json::serialize::to_string_pretty(&root).map_err(|e| ExportError::Json(e.to_string()))?;
    std::fs::write(path, text).map_err(|source| ExportError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The glTF document of [`write_gltf`], its buffer embedded as a `data:` URI.
pub fn document(
    info: &ModelInfo,
    trajectory: &Trajectory,
    options: &GltfOptions,
) -> Result<json::Root, ExportError> {
    let frames = Frames::new(info, trajectory)?;
    let up = options.up.resolve(&frames);
    let mut b = Builder::default();
    let nf = info.frames.len();

    // materials, one per colour
    let mut materials: BTreeMap<[u8; 3], json::Index<json::Material>> = BTreeMap::new();
    let mut material = |root: &mut json::Root, c: [u8; 3]| {
        *materials.entry(c).or_insert_with(|| {
            let f = |x: u8| (x as f32 / 255.0).powf(2.2); // sRGB → linear
            root.push(json::Material {
                pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                    base_color_factor: json::material::PbrBaseColorFactor([
                        f(c[0]),
                        f(c[1]),
                        f(c[2]),
                        1.0,
                    ]),
                    metallic_factor: json::material::StrengthFactor(0.0),
                    roughness_factor: json::material::StrengthFactor(0.7),
                    ..Default::default()
                },
                name: Some(format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])),
                ..Default::default()
            })
        })
    };

    // one mesh per frame with shapes (index nf: the ground), one primitive per shape
    let mut meshes: Vec<Option<json::Index<json::Mesh>>> = vec![None; nf + 1];
    for (slot, mesh) in meshes.iter_mut().enumerate() {
        let owner = (slot < nf).then_some(slot);
        let mut primitives = Vec::new();
        for shape in info.shapes.iter().filter(|s| s.frame == owner) {
            let tess = tessellate(shape);
            let mat = material(&mut b.root, palette(shape));
            let pos: Vec<f32> = tess.positions.iter().flatten().map(|&x| x as f32).collect();
            let positions = b.floats(
                &pos,
                json::accessor::Type::Vec3,
                Some(json::buffer::Target::ArrayBuffer),
            );
            let mut attributes = BTreeMap::new();
            attributes.insert(Valid(json::mesh::Semantic::Positions), positions);
            let (indices, mode): (Vec<u32>, _) = if tess.lines.is_empty() {
                let nor: Vec<f32> = tess.normals.iter().flatten().map(|&x| x as f32).collect();
                let normals = b.floats(
                    &nor,
                    json::accessor::Type::Vec3,
                    Some(json::buffer::Target::ArrayBuffer),
                );
                attributes.insert(Valid(json::mesh::Semantic::Normals), normals);
                (
                    tess.triangles().into_iter().flatten().collect(),
                    json::mesh::Mode::Triangles,
                )
            } else {
                (
                    tess.lines.iter().flatten().copied().collect(),
                    json::mesh::Mode::Lines,
                )
            };
            let indices = b.indices(&indices);
            primitives.push(json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(indices),
                material: Some(mat),
                mode: Valid(mode),
                targets: None,
            });
        }
        if !primitives.is_empty() {
            let name = owner.map_or("ground", |i| info.frames[i]).to_string();
            *mesh = Some(b.root.push(json::Mesh {
                extensions: None,
                extras: Default::default(),
                name: Some(name),
                primitives,
                weights: None,
            }));
        }
    }

    // nodes: one per body or frame at its first pose, the ground's shapes, under a root node
    let first = frames.pose(0);
    let mut children = Vec::new();
    let mut nodes = Vec::new();
    for i in 0..nf {
        let p = &first[i];
        let node = b.root.push(json::Node {
            mesh: meshes[i],
            name: Some(info.frames[i].to_string()),
            translation: Some(p.position.map(|x| x as f32)),
            rotation: Some(json::scene::UnitQuaternion(
                p.quaternion().map(|x| x as f32),
            )),
            ..Default::default()
        });
        nodes.push(node);
        children.push(node);
    }
    if meshes[nf].is_some() {
        children.push(b.root.push(json::Node {
            mesh: meshes[nf],
            name: Some("ground".into()),
            ..Default::default()
        }));
    }
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let top = b.root.push(json::Node {
        children: Some(children),
        name: Some(info.name.to_string()),
        rotation: match up {
            Up::Z => Some(json::scene::UnitQuaternion([-s, 0.0, 0.0, s])),
            _ => None,
        },
        ..Default::default()
    });
    let scene = b.root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: Some(info.name.to_string()),
        nodes: vec![top],
    });
    b.root.scene = Some(scene);

    // the animation: one time accessor, translation and rotation per node
    let t0 = frames.time(0);
    let times: Vec<f32> = (0..frames.len())
        .map(|k| (frames.time(k) - t0) as f32)
        .collect();
    let input = b.floats(&times, json::accessor::Type::Scalar, None);
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for (i, &node) in nodes.iter().enumerate() {
        let mut translation = Vec::with_capacity(3 * frames.len());
        let mut rotation = Vec::with_capacity(4 * frames.len());
        let mut previous = [0.0, 0.0, 0.0, 1.0];
        for k in 0..frames.len() {
            let p = &frames.pose(k)[i];
            translation.extend(p.position.map(|x| x as f32));
            // the sign of each quaternion nearest the previous one: no flips in between
            let mut q = p.quaternion();
            if (0..4).map(|c| q[c] * previous[c]).sum::<f64>() < 0.0 {
                q = q.map(|c| -c);
            }
            previous = q;
            rotation.extend(q.map(|x| x as f32));
        }
        for (path, data, ty) in [
            (
                json::animation::Property::Translation,
                translation,
                json::accessor::Type::Vec3,
            ),
            (
                json::animation::Property::Rotation,
                rotation,
                json::accessor::Type::Vec4,
            ),
        ] {
            let output = b.floats(&data, ty, None);
            let sampler = json::Index::push(
                &mut samplers,
                json::animation::Sampler {
                    extensions: None,
                    extras: Default::default(),
                    input,
                    interpolation: Valid(json::animation::Interpolation::Linear),
                    output,
                },
            );
            channels.push(json::animation::Channel {
                sampler,
                target: json::animation::Target {
                    extensions: None,
                    extras: Default::default(),
                    node,
                    path: Valid(path),
                },
                extensions: None,
                extras: Default::default(),
            });
        }
    }
    if !channels.is_empty() && frames.len() > 1 {
        b.root.push(json::Animation {
            extensions: None,
            extras: Default::default(),
            channels,
            name: Some("motion".into()),
            samplers,
        });
    }
    b.root.asset = json::Asset {
        generator: Some(format!("mbs {}", env!("CARGO_PKG_VERSION"))),
        version: "2.0".into(),
        ..Default::default()
    };
    let uri = format!("data:application/octet-stream;base64,{}", base64(&b.bytes));
    let len = b.bytes.len();
    b.root.push(json::Buffer {
        byte_length: USize64::from(len),
        name: None,
        uri: Some(uri),
        extensions: None,
        extras: Default::default(),
    });
    Ok(b.root)
}

/// The document and its one binary buffer, filled as accessors are added.
#[derive(Default)]
struct Builder {
    root: json::Root,
    bytes: Vec<u8>,
}

impl Builder {
    /// A buffer view over `data` (4-byte aligned) at the end of the buffer.
    fn view(
        &mut self,
        data: &[u8],
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        let offset = self.bytes.len();
        self.bytes.extend_from_slice(data);
        while self.bytes.len() % 4 != 0 {
            self.bytes.push(0);
        }
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(data.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    /// An accessor of f32 values of type `ty`, with its min and max per component.
    fn floats(
        &mut self,
        data: &[f32],
        ty: json::accessor::Type,
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::Accessor> {
        let n = ty.multiplicity();
        let mut min = vec![f32::INFINITY; n];
        let mut max = vec![f32::NEG_INFINITY; n];
        for chunk in data.chunks(n) {
            for (k, &x) in chunk.iter().enumerate() {
                min[k] = min[k].min(x);
                max[k] = max[k].max(x);
            }
        }
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(data.len() / n),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::F32,
            )),
            extensions: None,
            extras: Default::default(),
            type_: Valid(ty),
            min: Some(json!(min)),
            max: Some(json!(max)),
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// An accessor of u32 vertex indices.
    fn indices(&mut self, data: &[u32]) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(json::buffer::Target::ElementArrayBuffer));
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(data.len()),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::U32,
            )),
            extensions: None,
            extras: Default::default(),
            type_: Valid(json::accessor::Type::Scalar),
            min: None,
            max: None,
            name: None,
            normalized: false,
            sparse: None,
        })
    }
}

/// Standard base64 (RFC 4648, with padding).
pub fn base64(data: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(data.len().div_ceil(3) * 4);
    for chunk in data.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ShapeKind;

    const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    fn shape(kind: ShapeKind, at: [f64; 3]) -> ShapeInfo {
        ShapeInfo {
            frame: Some(0),
            kind,
            at,
            rotation: IDENTITY,
            color: None,
            declared: true,
        }
    }

    #[test]
    fn base64_matches_rfc_4648() {
        for (raw, enc) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(raw.as_bytes()), enc);
        }
    }

    #[test]
    fn closed_shapes_face_outwards_with_outward_normals() {
        let at = [0.3, -0.2, 1.0];
        for kind in [
            ShapeKind::Box {
                size: [0.1, 0.2, 0.4],
            },
            ShapeKind::Cylinder {
                radius: 0.1,
                length: 0.5,
                axis: 0,
            },
            ShapeKind::Cylinder {
                radius: 0.1,
                length: 0.5,
                axis: 2,
            },
            ShapeKind::Sphere { radius: 0.2 },
        ] {
            let t = tessellate(&shape(kind, at));
            assert_eq!(t.positions.len(), t.normals.len());
            for tri in t.triangles() {
                let [a, b, c] = tri.map(|i| t.positions[i as usize]);
                let (u, v) = (combo(&[(1.0, b), (-1.0, a)]), combo(&[(1.0, c), (-1.0, a)]));
                let n = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                let centroid = combo(&[(1.0 / 3.0, a), (1.0 / 3.0, b), (1.0 / 3.0, c)]);
                let out = combo(&[(1.0, centroid), (-1.0, at)]);
                let dot: f64 = (0..3).map(|k| n[k] * out[k]).sum();
                assert!(dot > 0.0, "{kind:?}: a triangle faces inwards");
                for i in tri {
                    let nv = t.normals[i as usize];
                    let norm: f64 = nv.iter().map(|x| x * x).sum::<f64>().sqrt();
                    assert!((norm - 1.0).abs() < 1e-12);
                    let d: f64 = (0..3).map(|k| nv[k] * n[k]).sum();
                    assert!(d > 0.0, "{kind:?}: a normal points inwards");
                }
            }
            // the extent along each axis
            let (lo, hi) =
                t.positions
                    .iter()
                    .fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
                        (
                            [0, 1, 2].map(|k| lo[k].min(p[k])),
                            [0, 1, 2].map(|k| hi[k].max(p[k])),
                        )
                    });
            let half = match kind {
                ShapeKind::Box { size } => size.map(|s| s / 2.0),
                ShapeKind::Cylinder {
                    radius,
                    length,
                    axis,
                } => {
                    let mut h = [radius; 3];
                    h[axis] = length / 2.0;
                    h
                }
                ShapeKind::Sphere { radius } => [radius; 3],
                ShapeKind::Line { .. } => unreachable!(),
            };
            for k in 0..3 {
                assert!((hi[k] - at[k] - half[k]).abs() < 1e-12, "{kind:?} {hi:?}");
                assert!((at[k] - lo[k] - half[k]).abs() < 1e-12, "{kind:?} {lo:?}");
            }
        }
    }
}
