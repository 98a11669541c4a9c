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
//! [`Up`]) hangs below a root node turned by −90° about x, and the body
//! nodes keep the model's world coordinates. Animation times are `t − t₀`, as 32-bit floats:
//! outputs closer together than their resolution (a millisecond at 10⁴ s) are skipped, and a
//! time or position beyond their range (3.4e38) is an [`ExportError`].

use crate::export::{ExportError, Frames, Up, palette};
use crate::model::ModelInfo;
use crate::trajectory::Trajectory;
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};
use serde_json::json;
use std::collections::BTreeMap;
use std::path::Path;

pub use crate::export::{ROUND_SEGMENTS, SPHERE_RINGS, Tessellation, tessellate};

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

/// Refuses a time or a frame's position beyond f32 (which glTF's JSON would write as `null`).
fn check_single_precision(info: &ModelInfo, frames: &Frames) -> Result<(), ExportError> {
    let t0 = frames.time(0);
    for k in 0..frames.len() {
        let t = frames.time(k);
        let beyond = |what: String, value: f64| ExportError::BeyondSinglePrecision {
            what,
            output: frames.output(k),
            t,
            value,
        };
        if !((t - t0) as f32).is_finite() {
            return Err(beyond("the time less the first output's".into(), t - t0));
        }
        for (i, p) in frames.pose(k).iter().enumerate() {
            if let Some(&x) = p.position.iter().find(|x| !(**x as f32).is_finite()) {
                return Err(beyond(format!("the position of `{}`", info.frames[i]), x));
            }
        }
    }
    Ok(())
}

/// The glTF document of [`write_gltf`], its buffer embedded as a `data:` URI.
pub fn document(
    info: &ModelInfo,
    trajectory: &Trajectory,
    options: &GltfOptions,
) -> Result<json::Root, ExportError> {
    let mut frames = Frames::new(info, trajectory)?;
    frames.keep_single_precision_times();
    check_single_precision(info, &frames)?;
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
}
