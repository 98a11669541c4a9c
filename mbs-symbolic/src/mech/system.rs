//! The checked description of a multibody system: what the DSL means, independent of syntax.
//! The DSL checker produces it; tests and tools may also build it directly.

use crate::expr::{Arena, ExprId, Var};

/// A multibody system: parameters, coordinates, frames given by products of elementary
/// transforms, points, effects and scenes, with all expressions in one [`Arena`].
#[derive(Clone, Debug)]
pub struct System {
    pub arena: Arena,
    /// type name of the generated model
    pub name: String,
    /// doc lines of the model
    pub docs: Vec<String>,
    pub params: Vec<ParamDef>,
    pub dofs: Vec<DofDef>,
    /// names of the inputs `u[k]`
    pub inputs: Vec<String>,
    /// bodies and massless frames, parents before children
    pub frames: Vec<FrameDef>,
    pub points: Vec<PointDef>,
    pub effects: Vec<EffectDef>,
    /// declared scenes; none means one model with every effect
    pub scenes: Vec<SceneDef>,
    /// holonomic constraints Φ(q, t) = 0 (closed loops, driving constraints)
    pub constraints: Vec<ConstraintDef>,
    /// shapes to draw (`shape` statements), evaluated with the default parameters
    pub shapes: Vec<ShapeDef>,
    /// spherical and free joints, whose charts are `Factor::Chart(j)`
    pub rotation_joints: Vec<RotationJointDef>,
    pub options: Options,
}

/// A shape drawn with a frame (`shape BODY: box(…);`): numbers, the values of its
/// expressions with the default parameters. Lengths in the frame's axes.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeDef {
    /// `None`: the ground
    pub frame: Option<usize>,
    pub geometry: Geometry,
    /// centre in the frame's axes (zero for a line)
    pub at: [f64; 3],
    /// columns: the shape's axes in the frame's axes
    pub rotation: [[f64; 3]; 3],
    pub color: Option<[u8; 3]>,
    /// false for a body's default shape (its equivalent box)
    pub declared: bool,
}

/// What a [`ShapeDef`] is, in its own axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Geometry {
    Box([f64; 3]),
    /// radius, length, axis (0, 1, 2)
    Cylinder(f64, f64, usize),
    Sphere(f64),
    /// from, to
    Line([f64; 3], [f64; 3]),
}

/// The identity rotation.
pub const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

#[derive(Clone, Debug)]
pub struct ParamDef {
    pub name: String,
    pub default: f64,
    /// `param k = 1e4 sensitive;`: the model gets ∂τ/∂k (`Model::parameter_tangents`)
    pub sensitive: bool,
}

#[derive(Clone, Debug)]
pub struct DofDef {
    /// `q[3]` for an indexed coordinate, or the user's name (`knee`)
    pub name: String,
    /// initial position (an expression of parameters)
    pub q0: ExprId,
    /// initial velocity (an expression of parameters)
    pub qd0: ExprId,
    /// kept at its value when a closed loop is assembled
    pub independent: bool,
}

/// Mass and inertia tensor about G in body axes.
#[derive(Clone, Copy, Debug)]
pub struct Inertia {
    pub mass: ExprId,
    /// tensor components xx, yy, zz, xy, xz, yz (the tensor's entries, so I_xy = −∫xy dm)
    pub tensor: [ExprId; 6],
}

/// One elementary factor of a transform product.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Factor {
    /// `Tdisp(x, y, z)`: translation, in the axes of the frame it starts from
    Disp([ExprId; 3]),
    /// `Trotx/Troty/Trotz(a)`, `Trotn(nx, ny, nz, a)`: rotation by `angle` about the unit `axis`
    Rot { axis: [ExprId; 3], angle: ExprId },
    /// the chart of rotation joint `j` ([`System::rotation_joints`]): a rotation by the
    /// matrix the model holds at run time ([`crate::expr::Var::Chart`]), constant between
    /// re-centrings; `Tball(a, b, c)` is `Chart(j)·Rz(a)·Ry(b)·Rx(c)`
    Chart(u16),
}

/// A spherical joint `Tball(a, b, c)` or a free joint `Tfree(x, y, z, a, b, c)`: ZYX angles
/// (a, b, c) measured from a chart the runtime re-centres before they reach gimbal lock
/// (cos b = 0), after a translation (x, y, z) in the axes of the frame before the joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RotationJointDef {
    /// the first frame whose pose contains the joint
    pub frame: usize,
    /// the coordinates of a, b, c
    pub angles: [usize; 3],
    /// `Tfree`: the coordinates of x, y, z
    pub translation: Option<[usize; 3]>,
}

/// A body (with inertia) or a massless frame. Its frame is at G for a body.
#[derive(Clone, Debug)]
pub struct FrameDef {
    pub name: String,
    /// the frame the product starts from (`TOG[parent] * …`); `None` is the ground
    pub parent: Option<usize>,
    pub factors: Vec<Factor>,
    /// `None` for a massless frame
    pub inertia: Option<Inertia>,
}

/// A point fixed on a frame (or on the ground).
#[derive(Clone, Debug)]
pub struct PointDef {
    pub name: String,
    pub frame: Option<usize>,
    /// position in the frame's axes, relative to its origin
    pub pos: [ExprId; 3],
}

/// Where a force acts: a frame (or the ground) and a position in its axes.
#[derive(Clone, Copy, Debug)]
pub struct Attach {
    pub frame: Option<usize>,
    pub pos: [ExprId; 3],
}

/// Something an effect applies.
#[derive(Clone, Debug)]
pub enum Load {
    /// uniform gravity (world components); conservative
    Gravity([ExprId; 3]),
    /// spring with stiffness `k`, rest length `l0` and preload `preload` between two points,
    /// acting along the line between them, or along the fixed world direction `axis` (a
    /// linear spring whose length is the signed distance along the axis): tension
    /// F0 + k (l − l0), potential F0 (l − l0) + ½ k (l − l0)²; conservative
    Spring {
        a: Attach,
        b: Attach,
        k: ExprId,
        l0: ExprId,
        axis: Option<[ExprId; 3]>,
        /// tension at the rest length, F0 (0: none)
        preload: ExprId,
    },
    /// linear damper between two points, along their line or the world direction `axis`
    Damper {
        a: Attach,
        b: Attach,
        c: ExprId,
        axis: Option<[ExprId; 3]>,
    },
    /// a force at a point, components in `frame`'s axes (`None`: world)
    Force {
        at: Attach,
        force: [ExprId; 3],
        frame: Option<usize>,
    },
    /// a torque on `on`, components in `frame`'s axes (`None`: world), with the opposite
    /// torque on `reaction` when given (`Some(None)`: the ground)
    Torque {
        on: Option<usize>,
        torque: [ExprId; 3],
        frame: Option<usize>,
        reaction: Option<Option<usize>>,
    },
    /// a generalised force on one coordinate
    GenForce { dof: usize, value: ExprId },
    /// penalty contact of a point, or of a sphere of radius `radius` centred at it, with the
    /// fixed world plane n·x = `offset` (n unit, pointing out of the ground). With the
    /// penetration δ = offset + radius − n·x and its rate δ̇ = −n·v: normal force
    /// F_n = step(δ) pos(k δ + c δ̇) along n (never pulling), regularised Coulomb friction
    /// F_t = −μ F_n v_t / sqrt(|v_t|² + eps²) at the contact point x − radius·n (v_t its
    /// velocity less its normal part). The elastic part k pos(δ) derives from the potential
    /// ½ k pos(δ)²; damping and friction count in the power.
    ///
    /// With `ellipsoid` (semi-axes along the axes of `at`'s frame, centred at `at`), δ is the
    /// depth of the ellipsoid's support point along −n, where the forces act. With `exponent`
    /// e and `dissipation` d (Hunt–Crossley), F_n = step(δ) pos(k pos(δ)^e (1 + d δ̇) + c δ̇),
    /// potential k pos(δ)^(e+1) / (e + 1)
    Contact {
        at: Attach,
        /// 0 for a point
        radius: ExprId,
        /// semi-axes of an ellipsoid in the axes of `at`'s frame
        ellipsoid: Option<[ExprId; 3]>,
        /// exponent e ≥ 1 of the elastic force k pos(δ)^e (1 for a linear contact)
        exponent: ExprId,
        /// Hunt–Crossley dissipation d ≥ 0 (s/m): the elastic force times (1 + d δ̇)
        dissipation: ExprId,
        normal: [ExprId; 3],
        offset: ExprId,
        k: ExprId,
        c: ExprId,
        mu: ExprId,
        eps: ExprId,
    },
    /// six-axis linear spring–damper between the origins and orientations of frames `a` and
    /// `b` (`None`: the ground), diagonal stiffnesses and dampings in `a`'s axes; see
    /// `mech::effects::bushing` for the formulas. The elastic part derives from the potential
    /// ½ Δpᵀ K Δp + ½ θᵀ K_r θ; damping counts in the power
    Bushing {
        a: Option<usize>,
        b: Option<usize>,
        k: [ExprId; 3],
        kr: [ExprId; 3],
        c: [ExprId; 3],
        cr: [ExprId; 3],
    },
    /// linear rotational spring–damper about the unit `axis` (in `a`'s axes) between frames
    /// `a` and `b` (`None`: the ground): with θ the angle of `b` relative to `a` about the
    /// axis, the torque −k (θ − θ0) − c θ̇ about the axis on `b` and the opposite on `a`
    /// (the generalised forces −(k (θ − θ0) + c θ̇) ∂θ/∂q); see
    /// `mech::effects::rotational_spring` for θ. Potential ½ k (θ − θ0)²; power −c θ̇²
    RotationalSpring {
        a: Option<usize>,
        b: Option<usize>,
        axis: [ExprId; 3],
        k: ExprId,
        c: ExprId,
        angle0: ExprId,
    },
}

impl Load {
    /// Gravity and springs derive from a potential; the rest do work counted as power
    /// (contacts and bushings have both a potential and a power).
    pub fn is_conservative(&self) -> bool {
        matches!(self, Load::Gravity(_) | Load::Spring { .. })
    }
}

#[derive(Clone, Debug)]
pub struct EffectDef {
    /// effect name; `None` for statements outside any `effect` block (always on)
    pub name: Option<String>,
    pub loads: Vec<Load>,
}

#[derive(Clone, Debug)]
pub struct SceneDef {
    pub name: String,
    /// indices into `effects` (always-on effects are added automatically)
    pub effects: Vec<usize>,
}

/// One scalar constraint Φ(q, t) = 0, named.
#[derive(Clone, Debug)]
pub struct ConstraintDef {
    /// `drive`, or `loop.x` for one direction of a closure
    pub name: String,
    pub kind: ConstraintKind,
}

/// What a constraint says.
#[derive(Clone, Copy, Debug)]
pub enum ConstraintKind {
    /// Φ = the expression (of q, t and parameters)
    Scalar(ExprId),
    /// the two points coincide along axis `axis` (0, 1, 2) of `frame` (`None`: world):
    /// Φ = e · (x_b − x_a)
    Coincide {
        a: Attach,
        b: Attach,
        axis: usize,
        frame: Option<usize>,
    },
    /// frame `b` does not turn relative to frame `a` about `a`'s axis `axis`:
    /// Φ = ½ (e_{i,a} · e_{j,b} − e_{j,a} · e_{i,b}), (axis, i, j) a cyclic permutation
    Align {
        a: Option<usize>,
        b: Option<usize>,
        axis: usize,
    },
}

/// Which equations-of-motion formulation to emit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Formulation {
    /// Σ Jᵀ m J with Jacobians composed along the tree (the seed's)
    VirtualPower,
    /// Newton–Euler for h and τ, composite inertia for M
    Recursive,
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    /// emit exact tangents K_t = ∂τ/∂q and C_t = ∂τ/∂qd
    pub tangents: bool,
    /// the form of the tangents' code (`option tangents = table;`)
    pub tangent_form: TangentForm,
    /// emit `dynamics_x4` and `forward_dynamics_x4`: four states at once on SIMD lanes
    pub batch: bool,
    /// emit `motion`, the poses and velocities of `kinematics` without its Jacobians, and
    /// `transmit`, the generalised forces of wrenches by one inward pass of the tree
    pub motion: bool,
    /// force a formulation; `None` picks the cheaper by op count
    pub formulation: Option<Formulation>,
    /// force the form of the Jacobians of `kinematics` and `point_kinematics` and of M;
    /// `None` picks by the size of the model (`SymbolicModel::assembled`)
    pub jacobians: Option<Jacobians>,
}

/// How the tangents are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TangentForm {
    /// straight-line code, as every other function
    #[default]
    Code,
    /// a table of operations the runtime reads in a loop (`mbs::__private::tape`): far less
    /// for rustc to check, each operation read from the table at run time
    Table,
}

/// How `kinematics` and `point_kinematics` give the Jacobians of frames and points, and
/// `dynamics` and `mass_matrix` give M.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Jacobians {
    /// every column and every entry as generated code (O(n²) code on a chain)
    Generated,
    /// the twists of the coordinates and the composite inertias generated (O(n) code), the
    /// columns and M summed from them at run time (`mbs::__private::TwistTree`)
    Assembled,
}

impl System {
    /// An empty system named `name`.
    pub fn new(name: &str) -> System {
        System {
            arena: Arena::new(),
            name: name.to_string(),
            docs: Vec::new(),
            params: Vec::new(),
            dofs: Vec::new(),
            inputs: Vec::new(),
            frames: Vec::new(),
            points: Vec::new(),
            effects: Vec::new(),
            scenes: Vec::new(),
            constraints: Vec::new(),
            shapes: Vec::new(),
            rotation_joints: Vec::new(),
            options: Options::default(),
        }
    }

    pub fn ndof(&self) -> usize {
        self.dofs.len()
    }

    /// The frames, parents before children. A body may be declared before the frame its
    /// pose starts from; poses refer only to poses defined above them, so there is no cycle.
    pub fn frames_parents_first(&self) -> Vec<usize> {
        let n = self.frames.len();
        let mut order = Vec::with_capacity(n);
        let mut placed = vec![false; n];
        for i in 0..n {
            let mut chain = Vec::new();
            let mut f = Some(i);
            while let Some(j) = f.filter(|&j| !placed[j]) {
                assert!(chain.len() < n, "the poses of frames form a cycle");
                chain.push(j);
                f = self.frames[j].parent;
            }
            for &j in chain.iter().rev() {
                placed[j] = true;
                order.push(j);
            }
        }
        order
    }

    /// The effects active in scene `s` (`None`: the model without scenes, every effect).
    pub fn scene_effects(&self, s: Option<usize>) -> Vec<usize> {
        match s {
            None => (0..self.effects.len()).collect(),
            Some(i) => {
                let mut v: Vec<usize> = (0..self.effects.len())
                    .filter(|&e| self.effects[e].name.is_none())
                    .collect();
                v.extend(&self.scenes[i].effects);
                v.sort_unstable();
                v.dedup();
                v
            }
        }
    }

    /// Default parameter values, in declaration order.
    pub fn param_defaults(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.default).collect()
    }
}

/// Building a system in code (the DSL's checker does the same from tokens).
impl System {
    /// Declares a parameter; returns its expression.
    pub fn param(&mut self, name: &str, default: f64) -> ExprId {
        self.params.push(ParamDef {
            name: name.into(),
            default,
            sensitive: false,
        });
        self.arena.var(Var::Param((self.params.len() - 1) as u16))
    }

    /// Declares a coordinate with its initial position and velocity; returns its index.
    pub fn dof(&mut self, name: &str, q0: f64, qd0: f64) -> usize {
        let (q0, qd0) = (self.arena.num(q0), self.arena.num(qd0));
        self.dofs.push(DofDef {
            name: name.into(),
            q0,
            qd0,
            independent: false,
        });
        self.dofs.len() - 1
    }

    /// `q[i]`
    pub fn q(&mut self, i: usize) -> ExprId {
        self.arena.var(Var::Q(i as u16))
    }

    /// `qd[i]`
    pub fn qd(&mut self, i: usize) -> ExprId {
        self.arena.var(Var::Qd(i as u16))
    }

    /// time `t`
    pub fn t(&mut self) -> ExprId {
        self.arena.var(Var::T)
    }

    /// A constant.
    pub fn num(&mut self, v: f64) -> ExprId {
        self.arena.num(v)
    }

    /// A constant vector.
    pub fn vec3(&mut self, v: [f64; 3]) -> [ExprId; 3] {
        v.map(|x| self.arena.num(x))
    }

    /// Rotation by `angle` about `axis` (normalised here).
    pub fn rot(&mut self, axis: [f64; 3], angle: ExprId) -> Factor {
        let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let axis = self.vec3(axis.map(|x| x / n));
        Factor::Rot { axis, angle }
    }

    /// Constant displacement.
    pub fn disp(&mut self, d: [f64; 3]) -> Factor {
        Factor::Disp(self.vec3(d))
    }

    /// A spherical joint on coordinates `angles` (ZYX), or a free joint with the
    /// translation coordinates `translation` in front, for frame `frame`: its factors.
    pub fn rotation_joint(
        &mut self,
        frame: usize,
        angles: [usize; 3],
        translation: Option<[usize; 3]>,
    ) -> Vec<Factor> {
        self.rotation_joints.push(RotationJointDef {
            frame,
            angles,
            translation,
        });
        let j = (self.rotation_joints.len() - 1) as u16;
        let mut f = Vec::new();
        if let Some(t) = translation {
            f.push(Factor::Disp(t.map(|k| self.q(k))));
        }
        f.push(Factor::Chart(j));
        for (axis, k) in [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
            .into_iter()
            .zip(angles)
        {
            let angle = self.q(k);
            f.push(self.rot(axis, angle));
        }
        f
    }

    /// Declares a body (with `inertia`) or a massless frame at `TOG[parent] * factors…`;
    /// returns its index. The parent must have been declared before.
    pub fn frame(
        &mut self,
        name: &str,
        parent: Option<usize>,
        factors: Vec<Factor>,
        inertia: Option<Inertia>,
    ) -> usize {
        assert!(
            parent.is_none_or(|p| p < self.frames.len()),
            "parents come before children"
        );
        self.frames.push(FrameDef {
            name: name.into(),
            parent,
            factors,
            inertia,
        });
        self.frames.len() - 1
    }

    /// Mass and full inertia tensor (xx, yy, zz, xy, xz, yz) given as numbers.
    pub fn inertia(&mut self, mass: f64, tensor: [f64; 6]) -> Inertia {
        Inertia {
            mass: self.arena.num(mass),
            tensor: tensor.map(|x| self.arena.num(x)),
        }
    }

    /// Declares a point on a frame (`None`: the ground); returns its index.
    pub fn point(&mut self, name: &str, frame: Option<usize>, pos: [ExprId; 3]) -> usize {
        self.points.push(PointDef {
            name: name.into(),
            frame,
            pos,
        });
        self.points.len() - 1
    }

    /// Declares an effect (`None`: always on); returns its index.
    pub fn effect(&mut self, name: Option<&str>, loads: Vec<Load>) -> usize {
        self.effects.push(EffectDef {
            name: name.map(String::from),
            loads,
        });
        self.effects.len() - 1
    }

    /// Declares a scene made of effects.
    pub fn scene(&mut self, name: &str, effects: Vec<usize>) {
        self.scenes.push(SceneDef {
            name: name.into(),
            effects,
        });
    }
}
