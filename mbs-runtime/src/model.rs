//! The contract between generated models and the runtime.
//!
//! Matrices are slices in column-major order (`m[i + n*j]` is row i, column j), the layout of
//! nalgebra's `DMatrix`. Lengths are fixed by the model (`NQ`, `NU`, …); passing slices of
//! other lengths is a programming error and panics.

use crate::elements::cross;
use crate::error::{ModelError, ParamError};
use crate::lanes::{F64x4, LANES, lane_by_lane};
use serde::{Deserialize, Serialize, de::DeserializeOwned};
use std::fmt;

pub use crate::op_count::OpCount;

/// Serialized as a map of its five counts (the struct lives in a file the generator shares,
/// which has no serde).
impl Serialize for OpCount {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("OpCount", 5)?;
        st.serialize_field("adds", &self.adds)?;
        st.serialize_field("muls", &self.muls)?;
        st.serialize_field("divs", &self.divs)?;
        st.serialize_field("funcs", &self.funcs)?;
        st.serialize_field("lets", &self.lets)?;
        st.end()
    }
}

/// What a generated model is: names, sizes, formulation and op counts. Built by generated code.
#[derive(Debug)]
pub struct ModelInfo {
    /// type name of the generated model
    pub name: &'static str,
    /// scene name (empty for a model without scenes)
    pub scene: &'static str,
    /// coordinate names: `q[3]` or the DSL name
    pub dofs: &'static [&'static str],
    /// input names (`u[k]`)
    pub inputs: &'static [&'static str],
    /// bodies and massless frames, in declaration order
    pub frames: &'static [&'static str],
    /// whether each frame is a body (has mass)
    pub is_body: &'static [bool],
    /// declared points
    pub points: &'static [&'static str],
    /// parameter names, in declaration order
    pub params: &'static [&'static str],
    /// effects active in this model
    pub effects: &'static [&'static str],
    /// names of the scalar constraints Φ(q, t) = 0 (`loop.x`, `drive`…)
    pub constraints: &'static [&'static str],
    /// coordinates marked `independent` (kept when a closed loop is assembled)
    pub independent: &'static [bool],
    /// formulation of M and h: "recursive" or "virtual power"
    pub formulation: &'static str,
    /// whether `tangents` is generated
    pub has_tangents: bool,
    /// op counts per generated function
    pub ops: &'static [(&'static str, OpCount)],
    /// what to draw: the declared `shape` statements in order, then one default shape for
    /// each body that declares none (its equivalent box, `declared: false`)
    pub shapes: &'static [ShapeInfo],
    /// the joints written `Tball(…)` or `Tfree(…)`, in declaration order: their orientation
    /// is read in a chart the runtime moves ([`Model::chart`])
    pub rotation_joints: &'static [RotationJoint],
}

/// A spherical (`Tball(a, b, c)`) or free (`Tfree(x, y, z, a, b, c)`) joint. Its rotation is
/// `R_ref · Rz(a) · Ry(b) · Rx(c)` relative to the frame before it, where `R_ref`, the chart,
/// is a rotation matrix the model holds at run time ([`Model::chart`]) and (a, b, c) are ZYX
/// angles, singular where cos b = 0. The runtime keeps |cos b| away from 0 by re-centring:
/// it sets `R_ref` to the joint's current rotation and the angles to zero, which changes
/// neither the motion nor M's conditioning elsewhere.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct RotationJoint {
    /// the frame (body) the joint moves: an index into [`ModelInfo::frames`]
    pub frame: usize,
    /// the coordinates of a, b and c (indices into q)
    pub angles: [usize; 3],
    /// `Tfree`: the coordinates of the translation (x, y, z), along the axes of the frame
    /// before the joint, in front of the chart (so a re-centring leaves them unchanged);
    /// `None` for `Tball`
    pub translation: Option<[usize; 3]>,
}

/// The identity rotation, the chart of every rotation joint when a model is built.
pub const IDENTITY3: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A shape drawn with a body or frame (or the ground): a DSL `shape` statement, or the
/// default of a body that declares none. Lengths in the model's units, in the axes of the
/// frame, whose origin is G for a body; values are those of the default parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ShapeInfo {
    /// the body or frame it moves with (an index into [`ModelInfo::frames`]); `None`: the
    /// ground
    pub frame: Option<usize>,
    pub kind: ShapeKind,
    /// centre of the shape in the frame's axes (`at = (x, y, z)`); zero for a line, whose
    /// ends are given in the frame's axes
    pub at: [f64; 3],
    /// orientation: `rotation[i][j]`, column j is the shape's axis j in the frame's axes
    /// (the identity for declared shapes; the principal axes of inertia for a default box)
    pub rotation: [[f64; 3]; 3],
    /// `color = "#rrggbb"`; `None`: the viewer's choice
    pub color: Option<[u8; 3]>,
    /// false for the default shape of a body without `shape` statements
    pub declared: bool,
}

/// The geometry of a [`ShapeInfo`], in the shape's own axes, centred at its origin.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum ShapeKind {
    /// a box with edges `size` along the shape's x, y and z
    Box {
        size: [f64; 3],
    },
    /// a cylinder of `radius` and `length` along the shape's axis `axis` (0: x, 1: y, 2: z)
    Cylinder {
        radius: f64,
        length: f64,
        axis: usize,
    },
    Sphere {
        radius: f64,
    },
    /// a segment between two points of the frame (a rod, a cable: drawn as a line)
    Line {
        from: [f64; 3],
        to: [f64; 3],
    },
}

impl ShapeInfo {
    /// The point `p` of the shape's axes in the frame's axes: `at + rotation · p`.
    pub fn to_frame(&self, p: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        [0, 1, 2].map(|i| self.at[i] + r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2])
    }
}

/// The op-count table of a model's generated functions, for printing.
pub struct OpsTable<'a>(&'a ModelInfo);

impl fmt::Display for OpsTable<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{:<18} {:>7} {:>7} {:>7} {:>5} {:>6} {:>6}",
            "function", "flops", "adds", "muls", "divs", "funcs", "lets"
        )?;
        for (name, c) in self.0.ops {
            let [flops, adds, muls, divs, funcs, lets] = c.columns();
            writeln!(
                f,
                "{name:<18} {flops:>7} {adds:>7} {muls:>7} {divs:>5} {funcs:>6} {lets:>6}"
            )?;
        }
        Ok(())
    }
}

impl ModelInfo {
    /// The op counts of the generated functions as a table (`Display`).
    pub fn ops_table(&self) -> OpsTable<'_> {
        OpsTable(self)
    }

    /// Number of bodies (frames with mass).
    pub fn body_count(&self) -> usize {
        self.is_body.iter().filter(|&&b| b).count()
    }

    /// Index of the body or frame named `name`, for efforts written in Rust.
    pub fn frame_index(&self, name: &str) -> Option<usize> {
        self.frames.iter().position(|f| *f == name)
    }

    /// Index of the declared point named `name`.
    pub fn point_index(&self, name: &str) -> Option<usize> {
        self.points.iter().position(|p| *p == name)
    }

    /// `"q[3] (knee)"` for a named coordinate, `"q[3]"` otherwise.
    pub fn dof_label(&self, i: usize) -> String {
        match self.dofs.get(i) {
            Some(n) if n.starts_with("q[") => n.to_string(),
            Some(n) => format!("q[{i}] ({n})"),
            None => format!("q[{i}]"),
        }
    }
}

/// Kinetic and potential energy.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Energy {
    /// ½ Σ (m v_G² + ωᵀ Φ_G ω)
    pub kinetic: f64,
    /// gravity (from the world origin) and springs
    pub potential: f64,
}

impl Energy {
    pub fn total(&self) -> f64 {
        self.kinetic + self.potential
    }
}

/// Pose of a frame: `rotation[i][j]` (columns are the frame's axes in world axes) and the
/// world position of its origin (G for a body).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub rotation: [[f64; 3]; 3],
    pub position: [f64; 3],
}

impl Pose {
    /// The point `p` of the frame's axes in world axes: `position + rotation · p`.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        [0, 1, 2].map(|i| self.position[i] + r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2])
    }

    /// The rotation as a unit quaternion `[x, y, z, w]` (w ≥ 0), as glTF writes it.
    pub fn quaternion(&self) -> [f64; 4] {
        let r = &self.rotation;
        let tr = r[0][0] + r[1][1] + r[2][2];
        // Shepperd: divide by the largest of 4w², 4x², 4y², 4z²
        let q = if tr > r[0][0].max(r[1][1]).max(r[2][2]) {
            let s = 2.0 * (1.0 + tr).sqrt();
            [
                (r[2][1] - r[1][2]) / s,
                (r[0][2] - r[2][0]) / s,
                (r[1][0] - r[0][1]) / s,
                0.25 * s,
            ]
        } else if r[0][0] >= r[1][1] && r[0][0] >= r[2][2] {
            let s = 2.0 * (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt();
            [
                0.25 * s,
                (r[0][1] + r[1][0]) / s,
                (r[0][2] + r[2][0]) / s,
                (r[2][1] - r[1][2]) / s,
            ]
        } else if r[1][1] >= r[2][2] {
            let s = 2.0 * (1.0 - r[0][0] + r[1][1] - r[2][2]).sqrt();
            [
                (r[0][1] + r[1][0]) / s,
                0.25 * s,
                (r[1][2] + r[2][1]) / s,
                (r[0][2] - r[2][0]) / s,
            ]
        } else {
            let s = 2.0 * (1.0 - r[0][0] - r[1][1] + r[2][2]).sqrt();
            [
                (r[0][2] + r[2][0]) / s,
                (r[1][2] + r[2][1]) / s,
                0.25 * s,
                (r[1][0] - r[0][1]) / s,
            ]
        };
        let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        let sign = if q[3] < 0.0 { -1.0 } else { 1.0 };
        q.map(|c| sign * c / n)
    }
}

/// Kinematics of a body or frame, world axes.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FrameKinematics {
    pub pose: Pose,
    /// velocity of the origin
    pub velocity: [f64; 3],
    pub angular_velocity: [f64; 3],
    /// J_G = ∂v/∂qd, 3 × NQ column-major (`jv[3*k + i]`)
    pub jv: Vec<f64>,
    /// J_ω = ∂ω/∂qd, 3 × NQ column-major
    pub jw: Vec<f64>,
    /// acceleration of the origin at qdd = 0 (J̇_G·qd plus rheonomic terms)
    pub bias_acceleration: [f64; 3],
    /// angular acceleration at qdd = 0 (J̇_ω·qd plus rheonomic terms)
    pub bias_angular_acceleration: [f64; 3],
}

/// Kinematics of a declared point, world axes.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PointKinematics {
    pub position: [f64; 3],
    pub velocity: [f64; 3],
    /// ∂v/∂qd, 3 × NQ column-major
    pub jv: Vec<f64>,
    /// acceleration at qdd = 0
    pub bias_acceleration: [f64; 3],
}

/// Kinematics of every frame and point, filled by [`Model::kinematics`].
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Kinematics {
    pub frames: Vec<FrameKinematics>,
    pub points: Vec<PointKinematics>,
}

impl Kinematics {
    /// Buffers sized for `M` (allocates once; reuse it).
    pub fn new<M: Model>() -> Kinematics {
        let f = FrameKinematics {
            jv: vec![0.0; 3 * M::NQ],
            jw: vec![0.0; 3 * M::NQ],
            ..Default::default()
        };
        let p = PointKinematics {
            jv: vec![0.0; 3 * M::NQ],
            ..Default::default()
        };
        Kinematics {
            frames: vec![f; M::NFRAMES],
            points: vec![p; M::NPOINTS],
        }
    }
}

/// The tree of a generated model's twists, from which `kinematics` and `point_kinematics`
/// assemble the Jacobians of frames and points when the model generates the twists rather
/// than every column (`option jacobians = assembled;`, the default for large models): each
/// node of the tree moves with a twist per coordinate of its factor, (ω, v₀) in world axes
/// with v₀ the velocity at the world origin, and the column of coordinate j of a point p's
/// Jacobian is the sum over the nodes on p's path to the root of v₀ + ω × p (and of ω for a
/// frame's J_ω). `dynamics` and `mass_matrix` assemble M from the same twists and the
/// composite inertias of the nodes ([`TwistTree::mass_matrix`]). Used by generated code only.
#[doc(hidden)]
#[derive(Clone, Copy, Debug)]
pub struct TwistTree {
    /// of each node, the nearest of its ancestors that has twists (0, the root, when none
    /// has): the walks to the root skip the nodes of constant factors
    pub up: &'static [u32],
    /// the twists of node k are `first[k]..first[k + 1]`
    pub first: &'static [u32],
    /// the coordinate of each twist
    pub coordinate: &'static [u16],
    /// the node of each frame and each declared point (0 for a point fixed in the world)
    pub frame_node: &'static [u32],
    pub point_node: &'static [u32],
}

impl TwistTree {
    /// The Jacobians of the points, and of the frames when `frames`, from the twists `tw`
    /// (6 per twist: ω, then v₀) and the positions already in `out`.
    pub fn assemble(&self, tw: &[f64], out: &mut Kinematics, frames: bool) {
        if frames {
            for (f, &node) in out.frames.iter_mut().zip(self.frame_node) {
                f.jv.fill(0.0);
                f.jw.fill(0.0);
                self.along(node, tw, |j, x| {
                    add_column(&mut f.jv[j..j + 3], x, f.pose.position);
                    for (jw, w) in f.jw[j..j + 3].iter_mut().zip(x) {
                        *jw += w;
                    }
                });
            }
        }
        for (pk, &node) in out.points.iter_mut().zip(self.point_node) {
            pk.jv.fill(0.0);
            self.along(node, tw, |j, x| {
                add_column(&mut pk.jv[j..j + 3], x, pk.position)
            });
        }
    }

    /// Calls `f(3 × coordinate, twist)` for every twist from `node` to the root.
    #[inline(always)]
    fn along(&self, node: u32, tw: &[f64], mut f: impl FnMut(usize, &[f64; 6])) {
        let mut k = node as usize;
        while k != 0 {
            for t in self.first[k] as usize..self.first[k + 1] as usize {
                f(3 * self.coordinate[t] as usize, twist(tw, t));
            }
            k = self.up[k] as usize;
        }
    }

    /// M (NQ × NQ, column-major) by composite rigid bodies in world axes, from `mw`: the
    /// twists (6 each: ω, v₀), then per node with twists, in node order, its origin o and the
    /// composite inertia of its subtree about o (mass, first moment, inertia xx yy zz xy xz
    /// yz). For a twist t of node a, F = I_a ξ_t (linear m v + ω × h, angular I ω + h × v,
    /// with the velocities at o), and M gains ξ_s · F for every twist s of a and of its
    /// ancestors.
    pub fn mass_matrix(&self, mw: &[f64], n: usize, m: &mut [f64]) {
        m.fill(0.0);
        let (tw, nodes) = mw.split_at(6 * self.coordinate.len());
        let mut composites = nodes.chunks_exact(13);
        for a in 1..self.up.len() {
            let (t0, t1) = (self.first[a] as usize, self.first[a + 1] as usize);
            if t0 == t1 {
                continue;
            }
            let c = composites.next().expect("a composite per node with twists");
            let o = [c[0], c[1], c[2]];
            let (mass, h) = (c[3], [c[4], c[5], c[6]]);
            let i = [
                [c[7], c[10], c[11]],
                [c[10], c[8], c[12]],
                [c[11], c[12], c[9]],
            ];
            for t in t0..t1 {
                let x = twist(tw, t);
                let w = [x[0], x[1], x[2]];
                // the twist's velocity at o, then F = I_a ξ_t about o
                let wo = cross(w, o);
                let v = [x[3] + wo[0], x[4] + wo[1], x[5] + wo[2]];
                let (wh, hv) = (cross(w, h), cross(h, v));
                let lin = [0, 1, 2].map(|r| mass * v[r] + wh[r]);
                let ang =
                    [0, 1, 2].map(|r| i[r][0] * w[0] + i[r][1] * w[1] + i[r][2] * w[2] + hv[r]);
                // ... its moment about the world origin, where the twists' v₀ are: then
                // ξ_s · F = ω_s · (ang + o × lin) + v₀_s · lin
                let olin = cross(o, lin);
                let ang = [ang[0] + olin[0], ang[1] + olin[1], ang[2] + olin[2]];
                let ct = self.coordinate[t] as usize;
                let mut k = a;
                while k != 0 {
                    let last = if k == a {
                        t + 1
                    } else {
                        self.first[k + 1] as usize
                    };
                    for s in self.first[k] as usize..last {
                        let y = twist(tw, s);
                        let value = y[0] * ang[0]
                            + y[1] * ang[1]
                            + y[2] * ang[2]
                            + y[3] * lin[0]
                            + y[4] * lin[1]
                            + y[5] * lin[2];
                        // into the upper triangle (row ≤ column, down a column for the
                        // ancestors of a chain), mirrored at the end
                        let cs = self.coordinate[s] as usize;
                        let (r, c) = (cs.min(ct), cs.max(ct));
                        let twice = s != t && cs == ct;
                        m[r + n * c] += if twice { 2.0 * value } else { value };
                    }
                    k = self.up[k] as usize;
                }
            }
        }
        for c in 0..n {
            for r in 0..c {
                m[c + n * r] = m[r + n * c];
            }
        }
    }
}

/// Twist `t` of `tw`: (ω, v₀).
#[inline(always)]
fn twist(tw: &[f64], t: usize) -> &[f64; 6] {
    tw[6 * t..6 * t + 6].try_into().expect("6 values")
}

/// A column of a Jacobian += v₀ + ω × p, for the twist x = (ω, v₀).
#[inline(always)]
fn add_column(col: &mut [f64], x: &[f64; 6], p: [f64; 3]) {
    let wp = cross([x[0], x[1], x[2]], p);
    col[0] += x[3] + wp[0];
    col[1] += x[4] + wp[1];
    col[2] += x[5] + wp[2];
}

/// The derivatives [`Model::constraint_parameter_tangents`] writes, column-major, NS columns
/// by sensitive parameter in the order of [`Model::SENSITIVE`]. With Φ̇ = B qd + Φ_t and
/// Φ̈ = B qdd − γ (buffers sized for one model by [`ConstraintTangents::new`]):
#[derive(Clone, Debug, PartialEq)]
pub struct ConstraintTangents {
    /// ∂Φ/∂p (NC × NS)
    pub dphi_dp: Vec<f64>,
    /// ∂Φ̇/∂q (NC × NQ)
    pub drate_dq: Vec<f64>,
    /// ∂Φ̇/∂p (NC × NS)
    pub drate_dp: Vec<f64>,
    /// ∂Φ̈/∂q (NC × NQ)
    pub dacc_dq: Vec<f64>,
    /// ∂Φ̈/∂qd (NC × NQ)
    pub dacc_dqd: Vec<f64>,
    /// ∂Φ̈/∂p (NC × NS)
    pub dacc_dp: Vec<f64>,
    /// ∂(Bᵀλ)/∂p (NQ × NS)
    pub dforce_dp: Vec<f64>,
}

impl ConstraintTangents {
    /// Buffers of the sizes of model `M`.
    pub fn new<M: Model>() -> ConstraintTangents {
        let (n, nc, ns) = (M::NQ, M::NC, M::SENSITIVE.len());
        ConstraintTangents {
            dphi_dp: vec![0.0; nc * ns],
            drate_dq: vec![0.0; nc * n],
            drate_dp: vec![0.0; nc * ns],
            dacc_dq: vec![0.0; nc * n],
            dacc_dqd: vec![0.0; nc * n],
            dacc_dp: vec![0.0; nc * ns],
            dforce_dp: vec![0.0; n * ns],
        }
    }
}

/// Parameters of a generated model: a plain struct with `Default` = the DSL's values.
pub trait Parameters:
    Clone + fmt::Debug + Default + PartialEq + Serialize + DeserializeOwned
{
    /// Names, in declaration order.
    const NAMES: &'static [&'static str];
    /// Values, in declaration order.
    fn values(&self) -> Vec<f64>;
    /// Sets one parameter by name.
    fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError>;
    /// Checks values: finite, masses positive, inertias physical, stiffnesses ≥ 0.
    fn validate(&self) -> Result<(), ParamError>;
}

/// Buffers of NQ numbers each for [`Model::differenced_tangents`] and
/// [`Model::differenced_iteration_matrix`]: τ at the base and at a moved state, the moved
/// coordinates, rates and accelerations.
pub struct DifferenceBuffers<'a> {
    pub tau0: &'a mut [f64],
    pub tau1: &'a mut [f64],
    pub qp: &'a mut [f64],
    pub vp: &'a mut [f64],
    pub ap: &'a mut [f64],
}

/// The forward-difference increment of a value x: √ε·max(|x|, 1) as represented in floating
/// point, (x + δ) − x.
pub fn increment(x: f64) -> f64 {
    (x + f64::EPSILON.sqrt() * x.abs().max(1.0)) - x
}

/// [`Model::differenced_tangents`] as its default does it: τ differenced along each
/// coordinate's position and rate, 2·NQ + 1 evaluations of [`Model::inverse_dynamics`].
pub fn differenced_tangents<M: Model + ?Sized>(
    model: &M,
    t: f64,
    [q, qd, qdd]: [&[f64]; 3],
    u: &[f64],
    [k, c]: [&mut [f64]; 2],
    work: DifferenceBuffers<'_>,
) -> usize {
    let n = q.len();
    let DifferenceBuffers {
        tau0, tau1, qp, vp, ..
    } = work;
    model.inverse_dynamics(t, q, qd, qdd, u, tau0);
    qp.copy_from_slice(q);
    vp.copy_from_slice(qd);
    for j in 0..n {
        let eps = increment(q[j]);
        qp[j] = q[j] + eps;
        model.inverse_dynamics(t, qp, qd, qdd, u, tau1);
        qp[j] = q[j];
        for i in 0..n {
            k[i + n * j] = (tau1[i] - tau0[i]) / eps;
        }
        let eps = increment(qd[j]);
        vp[j] = qd[j] + eps;
        model.inverse_dynamics(t, q, vp, qdd, u, tau1);
        vp[j] = qd[j];
        for i in 0..n {
            c[i + n * j] = (tau1[i] - tau0[i]) / eps;
        }
    }
    2 * n + 1
}

/// [`Model::differenced_iteration_matrix`] as its default does it: NQ + 1 evaluations of
/// [`Model::inverse_dynamics`].
pub fn differenced_iteration_matrix<M: Model + ?Sized>(
    model: &M,
    t: f64,
    [q, qd, qdd]: [&[f64]; 3],
    u: &[f64],
    [beta, gamma]: [f64; 2],
    a: &mut [f64],
    work: DifferenceBuffers<'_>,
) -> usize {
    let n = q.len();
    let DifferenceBuffers {
        tau0,
        tau1,
        qp,
        vp,
        ap,
    } = work;
    model.inverse_dynamics(t, q, qd, qdd, u, tau0);
    qp.copy_from_slice(q);
    vp.copy_from_slice(qd);
    ap.copy_from_slice(qdd);
    for (j, column) in a.chunks_exact_mut(n).enumerate() {
        iteration_column(
            j,
            [q, qd, qdd],
            [beta, gamma],
            [&mut *qp, &mut *vp, &mut *ap],
            (tau0, &mut *tau1),
            column,
            |[qp, vp, ap], tau1| {
                model.inverse_dynamics(t, qp, vp, ap, u, tau1);
                true
            },
        );
    }
    n + 1
}

/// Column `j` of a differenced iteration matrix M + γ'C + β'K: moves coordinate j of the
/// state (`moved`, a copy of (q, qd, qdd)) by (β', γ', 1)·ε, ε = √ε·max(|qdd_j|, 1), has
/// `tau` evaluate τ there (into the second of `taus`), puts the state back and writes
/// (τ − τ₀)/ε into `column`, τ₀ the first of `taus`. False, and nothing written, where `tau`
/// fails.
pub(crate) fn iteration_column(
    j: usize,
    [q, qd, qdd]: [&[f64]; 3],
    [beta, gamma]: [f64; 2],
    [qp, vp, ap]: [&mut [f64]; 3],
    (tau0, tau1): (&[f64], &mut [f64]),
    column: &mut [f64],
    tau: impl FnOnce([&[f64]; 3], &mut [f64]) -> bool,
) -> bool {
    let eps = f64::EPSILON.sqrt() * qdd[j].abs().max(1.0);
    qp[j] += beta * eps;
    vp[j] += gamma * eps;
    ap[j] += eps;
    let ok = tau([qp, vp, ap], tau1);
    qp[j] = q[j];
    vp[j] = qd[j];
    ap[j] = qdd[j];
    if ok {
        for ((c, t1), t0) in column.iter_mut().zip(&*tau1).zip(tau0) {
            *c = (t1 - t0) / eps;
        }
    }
    ok
}

/// A model generated by `multibody!`: `M(q,t) qdd = h(q,qd,t)` and its companions.
pub trait Model {
    type Params: Parameters;
    /// number of coordinates
    const NQ: usize;
    /// number of inputs u
    const NU: usize;
    /// number of bodies and massless frames
    const NFRAMES: usize;
    /// number of declared points
    const NPOINTS: usize;
    /// number of scalar constraints Φ(q, t) = 0; the equations are then
    /// M qdd = h + Bᵀλ, Φ = 0 with B = ∂Φ/∂q
    const NC: usize;
    /// whether [`Model::forward_dynamics`] is generated (articulated bodies or sparse LᵀDL,
    /// no dense factorisation): the runtime then solves M qdd = h of an open-loop model with
    /// it; otherwise (models written by hand, `WithEfforts`) with a dense Cholesky of M
    const FORWARD_DYNAMICS_GENERATED: bool = false;
    /// whether [`Model::dynamics_x4`] and [`Model::forward_dynamics_x4`] are generated code
    /// on [`F64x4`] (`option batch;`); otherwise they call the one-state functions lane by
    /// lane
    const BATCH_GENERATED: bool = false;
    /// whether [`Model::motion`] and [`Model::transmit`] are generated (`option motion;`):
    /// the poses and velocities without Jacobians, and the generalised forces of wrenches by
    /// one inward pass of the tree; otherwise both go through [`Model::kinematics`]
    const MOTION_GENERATED: bool = false;
    /// the parameters marked `sensitive` in the model (`param k = 1e4 sensitive;`), in
    /// declaration order: the columns of [`Model::parameter_tangents`]
    const SENSITIVE: &'static [&'static str] = &[];
    /// The parameters whose sensitivities are coordinates of this model: a
    /// [`Sensitivities`](crate::Sensitivities) wrapper's, which treats the inputs as free of
    /// them (a sampled controller's feedback would be left out of dq/dp); 0 otherwise.
    const SENSITIVITY_BLOCKS: usize = 0;

    /// Names, sizes, formulation and op counts.
    fn info(&self) -> &'static ModelInfo;

    fn params(&self) -> &Self::Params;

    /// Replaces the parameters after validating them.
    fn set_params(&mut self, params: Self::Params) -> Result<(), ParamError>;

    /// Initial q (NQ) and qd (NQ) as declared in the DSL.
    fn initial_state(&self, q: &mut [f64], qd: &mut [f64]);

    /// Mass matrix M(q, t) (NQ × NQ).
    fn mass_matrix(&self, t: f64, q: &[f64], m: &mut [f64]);

    /// M (NQ × NQ) and h(q, qd, t, u) (NQ) together, sharing their common work.
    fn dynamics(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64], m: &mut [f64], h: &mut [f64]);

    /// qdd = M⁻¹ h at (t, q, qd, u) (NQ), with the pivot of every coordinate in the
    /// factorisation used (NQ): their product is det M, and a pivot that is not positive
    /// means M is singular there (qdd is then not finite). Generated models solve without a
    /// dense factorisation, by articulated bodies or by sparse LᵀDL, whichever the generator
    /// estimates quicker from its operations and its critical path (the op-count row
    /// `forward_dynamics (…)` names it); the default evaluates M and h
    /// and factorises M by dense Cholesky, allocating (models written by hand).
    fn forward_dynamics(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        u: &[f64],
        qdd: &mut [f64],
        pivots: &mut [f64],
    ) {
        let n = Self::NQ;
        let mut m = vec![0.0; n * n];
        self.dynamics(t, q, qd, u, &mut m, qdd);
        let ok = crate::linalg::cholesky(&mut m, n).is_ok();
        crate::linalg::solve_with_pivots(&m, n, ok, qdd, pivots);
    }

    /// [`Model::forward_dynamics`] with a generalised force `f` (NQ) added to h: qdd of
    /// M qdd = h + f, for efforts computed outside the model ([`crate::WithEfforts`]).
    /// Generated models solve it by the same function as `forward_dynamics` (which is this one
    /// at f = 0); the default solves densely, allocating.
    #[allow(clippy::too_many_arguments)]
    fn forward_dynamics_forced(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        u: &[f64],
        f: &[f64],
        qdd: &mut [f64],
        pivots: &mut [f64],
    ) {
        let n = Self::NQ;
        let mut m = vec![0.0; n * n];
        self.dynamics(t, q, qd, u, &mut m, qdd);
        for (a, f) in qdd.iter_mut().zip(f) {
            *a += f;
        }
        let ok = crate::linalg::cholesky(&mut m, n).is_ok();
        crate::linalg::solve_with_pivots(&m, n, ok, qdd, pivots);
    }

    /// [`Model::dynamics`] at four states at once (`t`, `q`, `qd`, `u`, `m`, `h` hold one
    /// state per lane, see [`crate::lanes`]). Generated with SIMD arithmetic when the model
    /// asks for it (`option batch;`, [`Model::BATCH_GENERATED`]); the default calls
    /// [`Model::dynamics`] lane by lane, allocating.
    #[allow(clippy::too_many_arguments)]
    fn dynamics_x4(
        &self,
        t: F64x4,
        q: &[F64x4],
        qd: &[F64x4],
        u: &[F64x4],
        m: &mut [F64x4],
        h: &mut [F64x4],
    ) {
        Self::dynamics_lanes([self; LANES], t, q, qd, u, m, h)
    }

    /// [`Model::dynamics_x4`] of four models of this type, lane `k` of `each[k]` with its
    /// parameters and charts (the members of an ensemble, [`crate::simulate_ensemble_each`]).
    /// Generated on lanes like [`Model::dynamics_x4`], which is this function with the model
    /// itself in every lane; the default calls [`Model::dynamics`] of each lane's model,
    /// allocating.
    #[allow(clippy::too_many_arguments)]
    fn dynamics_lanes(
        each: [&Self; LANES],
        t: F64x4,
        q: &[F64x4],
        qd: &[F64x4],
        u: &[F64x4],
        m: &mut [F64x4],
        h: &mut [F64x4],
    ) {
        lane_by_lane(t, [q, qd, u], [m, h], |k, t, [q, qd, u], [m, h]| {
            each[k].dynamics(t, q, qd, u, m, h)
        });
    }

    /// [`Model::forward_dynamics`] of four models of this type, as [`Model::dynamics_lanes`].
    #[allow(clippy::too_many_arguments)]
    fn forward_dynamics_lanes(
        each: [&Self; LANES],
        t: F64x4,
        q: &[F64x4],
        qd: &[F64x4],
        u: &[F64x4],
        qdd: &mut [F64x4],
        pivots: &mut [F64x4],
    ) {
        lane_by_lane(t, [q, qd, u], [qdd, pivots], |k, t, [q, qd, u], [a, p]| {
            each[k].forward_dynamics(t, q, qd, u, a, p)
        });
    }

    /// [`Model::forward_dynamics`] at four states at once, as [`Model::dynamics_x4`].
    #[allow(clippy::too_many_arguments)]
    fn forward_dynamics_x4(
        &self,
        t: F64x4,
        q: &[F64x4],
        qd: &[F64x4],
        u: &[F64x4],
        qdd: &mut [F64x4],
        pivots: &mut [F64x4],
    ) {
        Self::forward_dynamics_lanes([self; LANES], t, q, qd, u, qdd, pivots)
    }

    /// τ = M qdd − h (NQ): the generalised forces that produce qdd.
    fn inverse_dynamics(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        u: &[f64],
        tau: &mut [f64],
    );

    /// Exact tangents K_t = ∂τ/∂q and C_t = ∂τ/∂qd (NQ × NQ each), when generated
    /// (`option tangents;`).
    #[allow(clippy::too_many_arguments)]
    fn tangents(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        u: &[f64],
        k: &mut [f64],
        c: &mut [f64],
    ) -> Result<(), ModelError>;

    /// Whether [`Model::tangents`], where the model has them, are exact throughout: true for
    /// generated tangents, false for a wrapper that differences a part of them
    /// ([`crate::WithEfforts`]: its efforts written in Rust, by forward differences).
    fn tangents_exact(&self) -> bool {
        true
    }

    /// K_t = ∂τ/∂q and C_t = ∂τ/∂qd (NQ × NQ each, column-major, into `out`) at
    /// `state` = (q, qd, qdd) by forward differences of [`Model::inverse_dynamics`], what the schemes use without generated tangents; returns
    /// how many evaluations of τ it made. The default differences τ along each coordinate's
    /// position and rate, 2·NQ + 1 evaluations, each increment the one represented in floating
    /// point of √ε·max(|x|, 1). A wrapper that knows its structure may do less for the same
    /// numbers ([`crate::WithEfforts`]: the integrals of its extra states are read by nothing,
    /// and a change of an extra state leaves the wrapped model's kinematics as they are).
    fn differenced_tangents(
        &self,
        t: f64,
        state: [&[f64]; 3],
        u: &[f64],
        out: [&mut [f64]; 2],
        work: DifferenceBuffers<'_>,
    ) -> usize {
        differenced_tangents(self, t, state, u, out, work)
    }

    /// The iteration matrix M + γ'·C_t + β'·K_t (NQ × NQ, column-major; `weights` = [β', γ'])
    /// at `state` = (q, qd, qdd) by forward differences of [`Model::inverse_dynamics`] along (β'·e_j, γ'·e_j, e_j), the increment
    /// √ε·max(|qdd_j|, 1); returns how many evaluations of τ it made (NQ + 1 by default).
    /// [`crate::WithEfforts`] does less for the same numbers, as in
    /// [`Model::differenced_tangents`].
    fn differenced_iteration_matrix(
        &self,
        t: f64,
        state: [&[f64]; 3],
        u: &[f64],
        weights: [f64; 2],
        a: &mut [f64],
        work: DifferenceBuffers<'_>,
    ) -> usize {
        differenced_iteration_matrix(self, t, state, u, weights, a, work)
    }

    /// ∂q₀/∂p and ∂qd₀/∂p (NQ × NS each, column-major, NS = `SENSITIVE.len()`): how the
    /// declared start moves with each sensitive parameter (`dof x = x0;` with `param x0
    /// sensitive`), where the sensitivities start. Generated for the parameters marked
    /// `sensitive`; zero by default.
    fn start_sensitivities(&self, sq: &mut [f64], sqd: &mut [f64]) {
        sq.fill(0.0);
        sqd.fill(0.0);
    }

    /// ∂τ/∂p (NQ × NS, column-major, NS = `SENSITIVE.len()`) at (t, q, qd, qdd, u): how the
    /// generalised forces that produce qdd change with each sensitive parameter, all else
    /// fixed; τ = M qdd − h, so it is ∂M/∂p·qdd − ∂h/∂p (∂h/∂p alone at qdd = 0). Generated
    /// exactly for the parameters marked `sensitive`; an error for models without any.
    fn parameter_tangents(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        u: &[f64],
        dtau: &mut [f64],
    ) -> Result<(), crate::error::ModelError> {
        let _ = (t, q, qd, qdd, u, dtau);
        Err(crate::error::ModelError::NoSensitiveParameters {
            model: self.info().name,
        })
    }

    /// ∂M/∂p (NQ × NQ × NS: block j, column-major, is ∂M/∂pⱼ) and ∂h/∂p (NQ × NS,
    /// column-major) at (t, q, qd, u), exact: τ = M qdd − h is affine in qdd, so ∂h/∂p is
    /// −∂τ/∂p at qdd = 0 and column k of ∂M/∂pⱼ is ∂τ/∂pⱼ at qdd = e_k less that. NQ + 1
    /// evaluations of [`Model::parameter_tangents`], which is what the sensitivities use
    /// directly; an error for models without sensitive parameters.
    fn parameter_derivatives(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        u: &[f64],
        dm: &mut [f64],
        dh: &mut [f64],
    ) -> Result<(), crate::error::ModelError> {
        let (n, ns) = (Self::NQ, Self::SENSITIVE.len());
        let mut qdd = vec![0.0; n];
        self.parameter_tangents(t, q, qd, &qdd, u, dh)?;
        let mut col = vec![0.0; n * ns];
        for k in 0..n {
            qdd[k] = 1.0;
            self.parameter_tangents(t, q, qd, &qdd, u, &mut col)?;
            qdd[k] = 0.0;
            for j in 0..ns {
                for i in 0..n {
                    dm[i + n * k + n * n * j] = col[i + n * j] - dh[i + n * j];
                }
            }
        }
        for x in dh.iter_mut() {
            *x = -*x;
        }
        Ok(())
    }

    /// How the matrices of the motion about a state at rest (qd = qdd = 0) change: M,
    /// C = ∂τ/∂qd and K = ∂τ/∂q, each NQ × NQ·(1 + NS) column-major in blocks of NQ × NQ.
    /// Block 0 is the derivative along the coordinates' direction `dq` (Σₖ ∂X/∂qₖ dqₖ),
    /// block 1 + j the partial derivative by sensitive parameter j; along the equilibria,
    /// dX/dpⱼ = block 0 with `dq` = ∂q_eq/∂pⱼ, plus block 1 + j. Generated exactly for models
    /// with parameters marked `sensitive` and `option tangents;` (pole sensitivities); an
    /// error for the others.
    #[allow(clippy::too_many_arguments)]
    fn rest_tangent_derivatives(
        &self,
        t: f64,
        q: &[f64],
        dq: &[f64],
        u: &[f64],
        dm: &mut [f64],
        dc: &mut [f64],
        dk: &mut [f64],
    ) -> Result<(), crate::error::ModelError> {
        let _ = (t, q, dq, u, dm, dc, dk);
        Err(crate::error::ModelError::NoSensitiveParameters {
            model: self.info().name,
        })
    }

    /// With constraints and parameters marked `sensitive`: the derivatives of Φ, Φ̇ and Φ̈ and
    /// of the constraint forces Bᵀλ that the sensitivities of a closed loop need, at (t, q,
    /// qd, qdd, λ) ([`ConstraintTangents`]). Generated exactly; an error for other models.
    #[allow(clippy::too_many_arguments)]
    fn constraint_parameter_tangents(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        lambda: &[f64],
        out: &mut ConstraintTangents,
    ) -> Result<(), crate::error::ModelError> {
        let _ = (t, q, qd, qdd, lambda, out);
        Err(crate::error::ModelError::NoSensitiveParameters {
            model: self.info().name,
        })
    }

    /// With constraints, parameters marked `sensitive` and `option tangents;` (pole
    /// sensitivities of closed loops): how B (NC × NQ) and K_λ = ∂(Bᵀλ)/∂q (NQ × NQ) change,
    /// each NQ·(1 + NS) columns in blocks as [`Model::rest_tangent_derivatives`]: block 0
    /// along the coordinates' direction `dq`, block 1 + j by sensitive parameter j (λ held).
    /// Generated exactly; an error for other models.
    fn constraint_rest_derivatives(
        &self,
        t: f64,
        q: &[f64],
        dq: &[f64],
        lambda: &[f64],
        db: &mut [f64],
        dk: &mut [f64],
    ) -> Result<(), crate::error::ModelError> {
        let _ = (t, q, dq, lambda, db, dk);
        Err(crate::error::ModelError::NoSensitiveParameters {
            model: self.info().name,
        })
    }

    /// Called once the start of a closed loop is assembled (q and qd consistent with Φ = 0 and
    /// Φ̇ = 0), so that a wrapper can make the coordinates it adds consistent too (the
    /// sensitivities of the assembled start, [`crate::Sensitivities`]). Does nothing by default.
    fn complete_start(
        &self,
        t: f64,
        q: &mut [f64],
        qd: &mut [f64],
    ) -> Result<(), crate::error::Failure> {
        let _ = (t, q, qd);
        Ok(())
    }

    /// h(q, 0, t, u): forces at rest, for statics (NQ).
    fn static_forces(&self, t: f64, q: &[f64], u: &[f64], h: &mut [f64]);

    /// How many of the last coordinates are first-order states riding as velocities (the
    /// extra states of [`crate::WithEfforts`], `x:NAME`; none for generated models). Statics
    /// reads each from its coordinate's position, where [`Model::static_forces`] takes it,
    /// and solves ẋ = 0 for it (the state's integral means nothing at rest).
    fn first_order_states(&self) -> usize {
        0
    }

    /// ∂h/∂u (NQ × NU, column-major): how the inputs enter the equations (linearisation).
    fn input_matrix(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64], b: &mut [f64]);

    fn energy(&self, t: f64, q: &[f64], qd: &[f64]) -> Energy;

    /// Power of the non-conservative effects (dampers, forces, torques, generalised forces).
    fn power(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64]) -> f64;

    /// Φ(q, t) (NC).
    fn constraints(&self, t: f64, q: &[f64], phi: &mut [f64]);

    /// B = ∂Φ/∂q (NC × NQ, column-major).
    fn constraint_jacobian(&self, t: f64, q: &[f64], b: &mut [f64]);

    /// ∂Φ/∂t (NC): with B qd it gives Φ̇ = B qd + ∂Φ/∂t.
    fn constraint_rate(&self, t: f64, q: &[f64], phi_t: &mut [f64]);

    /// γ (NC) with B qdd = γ: the part of Φ̈ that does not depend on qdd, negated.
    fn constraint_bias(&self, t: f64, q: &[f64], qd: &[f64], gamma: &mut [f64]);

    /// ∂(Bᵀλ)/∂q (NQ × NQ, column-major), for Newton on constrained systems.
    fn constraint_tangent(&self, t: f64, q: &[f64], lambda: &[f64], k: &mut [f64]);

    /// Poses of every body and frame (NFRAMES).
    fn frames(&self, t: f64, q: &[f64], out: &mut [Pose]);

    /// Poses, velocities, Jacobians and bias accelerations of every frame and point.
    fn kinematics(&self, t: f64, q: &[f64], qd: &[f64], out: &mut Kinematics);

    /// The points' positions, velocities and Jacobians of [`Model::kinematics`] alone (in
    /// `out.points`; their bias accelerations and `out.frames` are left as they were): what
    /// efforts at points need ([`crate::Efforts::FRAMES`]). Generated models compute nothing
    /// else (the bias accelerations were a quarter of the walking hexapod's flops here), the
    /// default all of [`Model::kinematics`].
    fn point_kinematics(&self, t: f64, q: &[f64], qd: &[f64], out: &mut Kinematics) {
        self.kinematics(t, q, qd, out);
    }

    /// The poses and velocities of every frame and point of [`Model::kinematics`], without
    /// its Jacobians and bias accelerations (left as they were in `out`): what reads where
    /// frames and points are and how they move, as contacts and ground checks do. Models
    /// generated with `option motion;` compute nothing else (the human model's 12,227 flops
    /// of `kinematics` are 3,264 here), the default all of [`Model::kinematics`].
    fn motion(&self, t: f64, q: &[f64], qd: &[f64], out: &mut Kinematics) {
        self.kinematics(t, q, qd, out);
    }

    /// Writes into `qg` (NQ) the generalised forces Q = Σ J_vᵀ F + J_ωᵀ T of wrenches given in `f`,
    /// world axes: for frame i a force at its origin `f[6i..6i + 3]` and a torque
    /// `f[6i + 3..6i + 6]`, then for declared point j a force `f[6 NFRAMES + 3j..][..3]`
    /// (length 6 NFRAMES + 3 NPOINTS). Models generated with `option motion;` carry the
    /// wrenches to the coordinates by one inward pass of the tree, O(n), without a Jacobian
    /// ([`Model::MOTION_GENERATED`]); the default reads the Jacobians of
    /// [`Model::kinematics`] in buffers it allocates at each call.
    fn transmit(&self, t: f64, q: &[f64], f: &[f64], qg: &mut [f64])
    where
        Self: Sized,
    {
        let mut kin = Kinematics::new::<Self>();
        self.kinematics(t, q, &vec![0.0; Self::NQ], &mut kin);
        let three = |w: &[f64]| [w[0], w[1], w[2]];
        qg.fill(0.0);
        for (i, fr) in kin.frames.iter().enumerate() {
            crate::efforts::add_jt(qg, &fr.jv, three(&f[6 * i..]));
            crate::efforts::add_jt(qg, &fr.jw, three(&f[6 * i + 3..]));
        }
        let nf = Self::NFRAMES;
        for (j, p) in kin.points.iter().enumerate() {
            crate::efforts::add_jt(qg, &p.jv, three(&f[6 * nf + 3 * j..]));
        }
    }

    /// A failure of user code during the evaluations since the last call (efforts written in
    /// Rust, [`crate::WithEfforts`]), taken once; generated models have none.
    fn take_failure(&self) -> Option<crate::error::Failure> {
        None
    }

    /// Evaluations of user code so far (efforts written in Rust and their differences).
    fn user_evaluations(&self) -> usize {
        0
    }

    /// The chart of rotation joint `joint` ([`ModelInfo::rotation_joints`]): the reference
    /// rotation `R_ref` (`r[i][j]`: row i, column j) its angles are measured from. The
    /// identity when the model is built, and for models without rotation joints.
    fn chart(&self, joint: usize) -> [[f64; 3]; 3] {
        let _ = joint;
        IDENTITY3
    }

    /// Called after the runtime re-centred the charts of the rotation joints in `moved` and
    /// mapped the joints' angles and rates in q and qd (and their accelerations), so that a
    /// wrapper can map the coordinates it adds ([`crate::Sensitivities`]); returns whether
    /// the accelerations must be evaluated again at the mapped state (the runtime's map covers
    /// the joints' own). Does nothing by default.
    fn recentred(
        &self,
        moved: &[crate::charts::Recentring],
        q: &mut [f64],
        qd: &mut [f64],
    ) -> bool {
        let _ = (moved, q, qd);
        false
    }

    /// Moves the chart of rotation joint `joint` to `r` (a rotation matrix; the caller maps
    /// the joint's angles and rates so the motion does not change). Models without rotation
    /// joints ignore it.
    fn set_chart(&mut self, joint: usize, r: [[f64; 3]; 3]) {
        let _ = (joint, r);
    }
}

/// Each parameter of `model` whose value is not its default, set back to its default alone
/// (where the parameters stay valid), `holds` asked of the model so changed; the parameters
/// restored. The `(name, value, default)` of those for which it held, and whether every
/// parameter was at its default. What a failure at the start of a run, or of an analysis,
/// names as its cause ([`blamed_parameters`]).
pub(crate) fn defaults_for_which<M: Model>(
    model: &mut M,
    holds: &mut dyn FnMut(&M) -> bool,
) -> (Vec<(&'static str, f64, f64)>, bool) {
    let given = model.params().clone();
    let values = given.values();
    let defaults = M::Params::default().values();
    let mut found = Vec::new();
    for (k, name) in M::Params::NAMES.iter().enumerate() {
        if values[k].to_bits() == defaults[k].to_bits() {
            continue;
        }
        let mut p = given.clone();
        if p.set(name, defaults[k]).is_err() || model.set_params(p).is_err() {
            continue;
        }
        if holds(model) {
            found.push((*name, values[k], defaults[k]));
        }
    }
    // the given parameters were valid: they are again
    let _ = model.set_params(given);
    let all_default = values
        .iter()
        .zip(&defaults)
        .all(|(v, d)| v.to_bits() == d.to_bits());
    (found, all_default)
}

/// "; with `l` at its default 1 rather than 0 {what}: check that parameter", for the
/// parameters [`defaults_for_which`] found; empty when it found none.
pub(crate) fn blamed_parameters(found: &[(&'static str, f64, f64)], what: &str) -> String {
    if found.is_empty() {
        return String::new();
    }
    let named: Vec<String> = found
        .iter()
        .map(|(name, value, default)| {
            format!(
                "`{name}` at its default {} rather than {}",
                crate::error::short(*default),
                crate::error::short(*value)
            )
        })
        .collect();
    format!(
        "; with {} {what}: check {}",
        named.join(", or with "),
        if found.len() == 1 {
            "that parameter"
        } else {
            "those parameters"
        }
    )
}
