//! What the animation outputs share: the recorded poses an export plays (checked against the
//! model), the up axis ([`Up`]), the colour of each shape ([`palette`]), the shapes
//! as polygons ([`tessellate`]) and the error of an export ([`ExportError`]). [`crate::anim`]
//! (the HTML page) and [`crate::gltf`] (the glTF file) both build on this module and not on
//! each other.

use crate::model::{ModelInfo, Pose, ShapeInfo, ShapeKind};
use crate::trajectory::Trajectory;
use std::path::PathBuf;

/// Why a motion could not be exported.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("the trajectory has no output")]
    Empty,
    #[error(
        "the trajectory has no poses: simulate with `Options {{ frames: true, .. }}` to record them"
    )]
    NoPoses,
    #[error("the trajectory's bodies and frames {found:?} are not the model's {expected:?}")]
    Frames {
        expected: Vec<String>,
        found: Vec<String>,
    },
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot serialise the document: {0}")]
    Json(String),
    /// A value beyond what the file's 32-bit floats hold (about 3.4e38).
    #[error(
        "{what} at output {output} (t = {t}) is {value:e}, beyond the 32-bit floats of a glTF file: \
         export the outputs before it (a copy with `Trajectory::clear_outputs` and `push_output`)"
    )]
    BeyondSinglePrecision {
        what: String,
        output: usize,
        t: f64,
        value: f64,
    },
}

/// Which world axis points up in the views.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Up {
    /// `Y` when the motion stays in the xy plane (planar models, gravity along −y), `Z`
    /// otherwise
    #[default]
    Auto,
    Y,
    Z,
}

impl Up {
    /// `Y` or `Z`, deciding `Auto` from the motion.
    pub(crate) fn resolve(self, frames: &Frames) -> Up {
        match self {
            Up::Auto => {
                let first = frames.pose(0);
                let planar = (0..frames.len()).all(|k| {
                    frames.pose(k).iter().zip(first).all(|(p, p0)| {
                        (p.position[2] - p0.position[2]).abs() < 1e-9
                            && (p.rotation[2][2] - p0.rotation[2][2]).abs() < 1e-9
                    })
                });
                if planar { Up::Y } else { Up::Z }
            }
            u => u,
        }
    }
}

/// The outputs of a trajectory that an export plays: validated poses at strictly increasing
/// times (an output at the time of the previous one is skipped).
pub(crate) struct Frames<'a> {
    trajectory: &'a Trajectory,
    keep: Vec<usize>,
}

impl<'a> Frames<'a> {
    pub(crate) fn new(info: &ModelInfo, trajectory: &'a Trajectory) -> Result<Self, ExportError> {
        if trajectory.is_empty() {
            return Err(ExportError::Empty);
        }
        if trajectory.frame_names.len() != info.frames.len()
            || trajectory
                .frame_names
                .iter()
                .zip(info.frames)
                .any(|(a, b)| a != b)
        {
            return Err(ExportError::Frames {
                expected: info.frames.iter().map(|s| s.to_string()).collect(),
                found: trajectory.frame_names.clone(),
            });
        }
        if trajectory.poses.len() != trajectory.len() * info.frames.len() {
            return Err(ExportError::NoPoses);
        }
        let mut keep: Vec<usize> = Vec::with_capacity(trajectory.len());
        for (i, &t) in trajectory.t.iter().enumerate() {
            if keep.last().is_none_or(|&j| t > trajectory.t[j]) {
                keep.push(i);
            }
        }
        Ok(Frames { trajectory, keep })
    }

    /// Keeps at most `n` outputs (≥ 2), evenly in index, the first and last among them.
    /// (Only the HTML page thins; the glTF file keeps every output.)
    #[cfg(feature = "anim")]
    pub(crate) fn thin(&mut self, n: usize) {
        let n = n.max(2);
        if self.keep.len() > n {
            let m = self.keep.len() - 1;
            self.keep = (0..n).map(|k| self.keep[k * m / (n - 1)]).collect();
        }
    }

    /// Skips the outputs whose time, less the first's, rounds to the same 32-bit float as
    /// the previous kept output's (glTF's times are 32-bit and strictly increasing: at
    /// t − t₀ = 10⁴ s they are about a millisecond apart).
    #[cfg(feature = "gltf")]
    pub(crate) fn keep_single_precision_times(&mut self) {
        let t0 = self.time(0);
        let t = &self.trajectory.t;
        let mut last = f32::NEG_INFINITY;
        self.keep.retain(|&i| {
            let ti = (t[i] - t0) as f32;
            let keep = ti > last;
            if keep {
                last = ti;
            }
            keep
        });
    }

    /// The index in the trajectory of kept output `k`.
    pub(crate) fn output(&self, k: usize) -> usize {
        self.keep[k]
    }

    pub(crate) fn len(&self) -> usize {
        self.keep.len()
    }

    pub(crate) fn time(&self, k: usize) -> f64 {
        self.trajectory.t[self.keep[k]]
    }

    pub(crate) fn pose(&self, k: usize) -> &[Pose] {
        self.trajectory.poses_at(self.keep[k])
    }
}

/// Colours for shapes without their own, one per body or frame.
const PALETTE: [[u8; 3]; 8] = [
    [0x3b, 0x76, 0xc4],
    [0xe0, 0x7b, 0x39],
    [0x4a, 0xa8, 0x5e],
    [0xc8, 0x4b, 0x5b],
    [0x8e, 0x6c, 0xc0],
    [0xc9, 0xa2, 0x27],
    [0x3f, 0xa7, 0xb3],
    [0x9a, 0x6b, 0x4f],
];

/// The colour a shape is drawn in: its own, else one per frame (grey for the ground).
pub fn palette(shape: &ShapeInfo) -> [u8; 3] {
    match (shape.color, shape.frame) {
        (Some(c), _) => c,
        (None, Some(i)) => PALETTE[i % PALETTE.len()],
        (None, None) => [0x88, 0x88, 0x88],
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;

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
