//! # The `multibody!` language
//!
//! A `multibody!` block declares one or more models. Each body's position is a product of
//! homogeneous transforms in minimal coordinates, written as in EasyDyn's CAGeM; at compile
//! time the macro differentiates the positions, builds the equations of motion
//! `M(q,t) qdd = h(q,qd,t,u)` and emits a type implementing [`Model`](crate::Model).
//!
//! ```
//! mbs::multibody! {
//!     /// Planar double pendulum of two uniform bars.
//!     pub model DoublePendulum {
//!         param l = 1.0; param m = 1.0; param g = 9.81;
//!         dof q[0] = PI / 2; dof q[1] = 0.0;
//!         body bar1 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
//!         body bar2 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
//!         TOG[bar1] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
//!         TOG[bar2] = TOG[bar1] * Tdisp(0, -l/2, 0) * Trotz(q[1]) * Tdisp(0, -l/2, 0);
//!         effect gravity { gravity(0, -g, 0); }
//!         effect damping { torque(bar2, relative_to = bar1, axis = z, -0.05 * qd[1]); }
//!         scene Free = []; scene Swing = [gravity]; scene Full = [gravity, damping];
//!     }
//! }
//! use mbs::Model;
//! let model = DoublePendulumSwing::default();
//! let (mut m, mut h) = ([0.0; 4], [0.0; 2]);
//! model.dynamics(0.0, &[0.1, 0.2], &[0.0, 0.0], &[], &mut m, &mut h);
//! assert!(m[0] > m[3]);
//! ```
//!
//! ## Statements
//!
//! | statement | meaning |
//! |---|---|
//! | `param l = 1.0;` | a parameter: a field of the generated `…Params` struct, changeable at run time; its default is a constant expression |
//! | `param k = 1e4 sensitive;` | a parameter whose derivatives are generated: `Model::parameter_tangents` gives ∂τ/∂p of every sensitive parameter (through every `let` that uses it), `Model::SENSITIVE` names them; for statics (`analysis::static_sensitivity`), poles (`analysis::pole_sensitivity`, from `Model::rest_tangent_derivatives`: M, C, K's derivatives at rest, generated with `option tangents;`) and motions (`mbs::Sensitivities`, with `option tangents;`); with constraints, also `Model::constraint_parameter_tangents` (∂Φ/∂p, the derivatives of Φ̇ and Φ̈, ∂(Bᵀλ)/∂p) and, with `option tangents;`, `Model::constraint_rest_derivatives` (B′, K_λ′) for closed loops. Parameters not marked cost nothing |
//! | `let I = m*l*l/12;` | a named expression, substituted where used |
//! | `dof q[0] = PI/2;` | the next coordinate, with its initial value (default 0) |
//! | `dof knee = 0.2, qd = 1.0;` | a named coordinate with initial position and velocity; `knee`, `q[knee]`, `qd[knee]` refer to it |
//! | `input torque;` | the next input `u[k]`; `torque` or `u[k]` in effects |
//! | `body arm { mass = m; inertia = (Ixx, Iyy, Izz); }` | a body; its frame (TOG) is at its centre of gravity G |
//! | `inertia = (Ixx, Iyy, Izz, Ixy, Ixz, Iyz);` | full tensor about G in body axes; the entries are the tensor's (`Ixy = −∫xy dm`) |
//! | `body bar { mass = m; inertia_z = I; }` | a body that turns about its z axis only (planar models): its moment about z. It is stored as the tensor of a thin plate across z, `(I/2, I/2, I)`, a possible tensor whose other moments play no part while the body turns about z only; `inertia_x`, `inertia_y` likewise |
//! | `body point_mass { mass = 2.0; }` | a point mass (zero inertia) with its own pose |
//! | `mass tip on bar at (0, -l/2, 0) = 0.5;` | a point mass fixed on a body, at a point in its axes: a body `tip` of that mass and no inertia, its frame at the point (the same as `body tip { mass = 0.5; }` with `TOG[tip] = TOG[bar] * Tdisp(0, -l/2, 0);`); effects and shapes may name it, a pose may not start from it |
//! | `frame sensor;` | a massless frame (a secondary frame) |
//! | `point tip on arm at (0, -l/2, 0);` | a point fixed on a body, frame or `ground`, in its axes |
//! | `TOG[arm] = …;` | the body's pose: a product of transforms (below) |
//! | `fn g5(x) = 0.1*sin(x);` | an inline function, differentiated symbolically; its arguments hide the model's names of the same spelling in its own body only (a `let` or another `fn` it uses sees the model's) |
//! | `extern fn g6 = [knee::g6, knee::g6_d, knee::g6_dd];` | a Rust function `f64 -> f64` and its successive derivatives |
//! | `effect name { … }` | a named group of effect statements |
//! | `gravity(0, -g, 0);` … outside an `effect` | an effect that is always on |
//! | `scene Swing = [gravity];` | a model type `{Model}Swing` with those effects (plus the always-on ones) |
//! | `constraint drive = crank - w * t;` | a scalar constraint Φ(q, t) = 0 (closed loops, driving constraints) |
//! | `constraint close: coincide(a, b, along = [x, y]);` | two points meet along world axes (default x, y, z), or the axes of `frame = body`: one constraint per axis, named `close.x`, `close.y` |
//! | `constraint hinge: align(A, B, about = [x, y]);` | frame B keeps its orientation relative to A about A's axes: `hinge.rx`, `hinge.ry` |
//! | `dof crank = PI/3, independent;` | kept at its value when a closed loop is assembled |
//! | `option tangents;` | also generate exact K_t = ∂τ/∂q and C_t = ∂τ/∂qd |
//! | `option tangents = table;` | the same tangents, the same bits, written as a table of operations that one loop of the runtime reads: far less for rustc to check and no code to generate (the hexapod with tangents built in 3.1–3.8 s against 4.1–5.5 s, a program running it with Radau5 in 3.9–4.7 s against 8.8–16.2 s), each evaluation about 2.3× the time of the straight-line code (`option tangents = code;`, the default; a Radau5 run of the hexapod about a sixth longer); the measurements: `docs/compile_time.md` |
//! | `option batch;` | also generate `dynamics_x4` and `forward_dynamics_x4`: four states at once on SIMD lanes ([`crate::lanes`]; without the option they call the one-state functions lane by lane), and `dynamics_lanes` and `forward_dynamics_lanes`, the same with four models, each lane its model's parameters and charts, which ensembles of runs ([`crate::simulate_ensemble`], [`crate::simulate_ensemble_each`]) and sweeps over starts and parameters evaluate their stages on |
//! | `option motion;` | also generate `motion`: the poses and velocities of every frame and point of `kinematics`, without its Jacobians and bias accelerations ([`crate::Model::motion`]; without the option it computes all of `kinematics`), for code that reads where frames and points are and how they move and nothing else (the human model's ground checks and reports: 3,264 flops where `kinematics` takes 12,227); and `transmit`, the generalised forces of forces and torques on frames and points by one inward pass of the tree, O(n), without a Jacobian ([`crate::Model::transmit`]), which efforts written in Rust that read no Jacobian use ([`crate::Efforts::reads_jacobians`]) |
//! | `option formulation = recursive;` | force `recursive` or `virtual_power` (default: the cheaper by op count) |
//! | `shape arm: box(0.3, 0.05, 0.05);` | what to draw with a body, a frame or the `ground` (below); no effect on the dynamics |
//! | `for i in 0..n { … }`, `part Leg(k, x) { … }`, `Leg(0, 0.4);` | statements repeated with an index, templates instantiated with arguments; indexed names `bar[i]` ([below](#repetition-and-parts)) |
//!
//! Without scenes the model type is named after the model and has every effect. With scenes,
//! each scene is a type `{Model}{Scene}`; an effect a scene does not name has no code in it.
//! All scenes share the parameter struct `{Model}Params`.
//!
//! ## Transforms
//!
//! A pose is `TOG[parent] * F1 * F2 * …` or, CAGeM's absolute style, `F1 * F2 * …` from the
//! ground. Products that start with the same factors share them: the common prefix becomes a
//! massless intermediate frame. `TOG[i]` with a number refers to the i-th declared body or
//! frame. A product may only refer to bodies whose TOG comes earlier.
//!
//! | factor | meaning |
//! |---|---|
//! | `Tdisp(x, y, z)` | translation, in the axes of the frame it starts from |
//! | `Trotx(a)`, `Troty(a)`, `Trotz(a)` | rotation by `a` about x, y, z |
//! | `Trotn(nx, ny, nz, a)` | rotation by `a` about the unit axis (nx, ny, nz) |
//! | `Tball(a, b, c)` | a spherical joint: ZYX angles of three coordinates, in a chart the runtime re-centres before gimbal lock (below) |
//! | `Tfree(x, y, z, a, b, c)` | a free joint: the translation (x, y, z) in the axes of the frame it starts from, then `Tball(a, b, c)` |
//!
//! Arguments are expressions of `q`, `t` (rheonomic, imposed motion) and parameters, never of
//! velocities or inputs; those of `Tball` and `Tfree` are coordinates.
//!
//! ### Rotation joints
//!
//! Every set of three angles locks somewhere: ZYX angles (a, b, c) where cos b = 0, and a
//! model written with `Trotz(a) * Troty(b) * Trotx(c)` stops there with
//! `SingularConfiguration`. `Tball(a, b, c)` is the same rotation read in a chart `C` the
//! model holds, `R = C · Rz(a) · Ry(b) · Rx(c)` (`C` is the identity when the model is built,
//! so the declared initial angles mean what they say). After each accepted step the runtime
//! moves the chart of a joint whose |cos b| fell below `Options::chart_switch` (0.5) to the
//! joint's rotation and its angles to zero, its rates and accelerations mapped exactly: the
//! motion does not change, and the joint never reaches gimbal lock. The angles of a joint
//! thus have no fixed meaning and may appear in no other expression, force, pose or
//! constraint (a compile error); act on the orientation with a `torque`, a `bushing` or a
//! `rotational_spring` between frames, or a force at a point. A trajectory records each
//! joint's orientation as a quaternion and the chart of every output
//! ([`crate::Trajectory::orientation`], [`crate::Trajectory::chart`]).
//!
//! The same arguments again are the same joint (absolute poses repeat it); a coordinate
//! belongs to one joint. A `Tfree`'s translation comes before the chart and keeps its meaning
//! (it may be used elsewhere); at the root it is in world axes, which couples it to the
//! chart in M (the hexapod: 6,192 flops for M and h against 5,760 on Euler angles). Written
//! `Tball(a, b, c) * Tdisp(x, y, z)`, the translation is in the body's own axes and the chart
//! stays out of M (5,743), at the price of coordinates x, y, z that turn with the body.
//!
//! ```
//! mbs::multibody! {
//!     /// A top on its tip, its axis along body x.
//!     model Top {
//!         param w3 = 200.0;
//!         dof a = 0.0; dof b = -0.9; dof c = 0.0, qd = w3;
//!         body top { mass = 0.1; inertia = (4e-5, 2e-5, 2e-5); }
//!         TOG[top] = Tball(a, b, c) * Tdisp(0.04, 0, 0);
//!         gravity(0, 0, -9.81);
//!     }
//! }
//! use mbs::Model;
//! assert_eq!(Top::default().info().rotation_joints.len(), 1);
//! ```
//!
//! A translation along the axis of the rotation just before it commutes with that rotation,
//! and the generator moves it in front: `TOG[rotor] = TOG[arm] * Trotz(50 * q[0]) * Tdisp(0, 0,
//! 0.05)` is generated as `TOG[arm] * Tdisp(0, 0, 0.05) * Trotz(50 * q[0])`. A body whose
//! product ends with a rotation about x, y or z and whose inertia is symmetric about that
//! axis (a rotor, a wheel: `inertia = (i, i, i_spin)`, no products) costs no trigonometry of
//! its spin angle, whichever way the product is written.
//!
//! ```
//! mbs::multibody! {
//!     /// A cart carrying a pendulum, the track moved by an imposed motion.
//!     model Cart {
//!         param a = 0.05; param w = 3.0;
//!         dof x = 0.0; dof theta = 0.3;
//!         body cart { mass = 2.0; }
//!         body rod { mass = 0.5; inertia = (0.01, 0.0, 0.01); }
//!         TOG[cart] = Tdisp(x + a * sin(w * t), 0, 0);
//!         TOG[rod] = TOG[cart] * Trotz(theta) * Tdisp(0, -0.25, 0);
//!         gravity(0, -9.81, 0);
//!     }
//! }
//! ```
//!
//! ## Expressions
//!
//! Rust syntax and precedence: numbers, names, `+ - * /`, unary `-`, parentheses, `q[i]`,
//! `qd[i]`, `qdd[i]`, `u[k]`, `t`, the constants `PI`, `E`, `TAU`, and the functions `sin cos
//! tan asin acos atan atan2(y, x) sinh cosh tanh exp ln sqrt abs sign pos step powi(x, n)
//! pow(x, y)` (also as methods: `x.sin()`; `x.signum()` is `sign(x)`, the mathematical sign,
//! 0 at 0 where Rust's `f64::signum` gives 1). `^` is not a power; write `powi(x, 2)`.
//! `pos(x)` = max(x, 0) is the positive part (derivative `step(x)`) and `step(x)` is 1 for
//! x > 0, 0 otherwise (derivative 0): one-sided forces, such as a stop that only pushes,
//! `generalized_force(q[0], -k * pos(q[0] - 0.1))`. Exact tangents see their derivatives
//! away from the kink, not the jump. Where a power below 1 (`sqrt`, `pow(…, 0.7)`) or a
//! power with a varying exponent meets the kink of `pos(u)` or `abs(u)` (`sqrt(pos(x))`,
//! `pow(abs(v), 0.5)`, also scaled by numbers or parameters: `sqrt(abs(v) / v0)`,
//! `pow(c * pos(x), 0.7)`), whose derivative is infinite there, the generated derivative is
//! 0 at the kink rather than NaN (and below it, for `pos`).
//!
//! `spline(x, [(x0, y0), (x1, y1), …])` is the natural cubic spline through the points
//! (x0 < x1 < …, at least two; numbers known when the model is generated): cubic between
//! knots with continuous slope and curvature, zero curvature at both ends, and beyond the
//! ends the straight line of the end value and slope. Its derivatives are generated like any
//! other (up to the third, constant between knots), so a joint that is not a classical one —
//! a knee whose centre glides with its angle — is written with its published points:
//! `fn g5(a) = spline(a, [(-2.1, 0.012), (-1.4, 0.006), (0.0, 0.0)]);` then
//! `TOG[tibia] = TOG[femur] * Tdisp(g5(knee), g6(knee), 0) * Trotz(knee)`. Generated code holds
//! the tables as `Params::SPLINES` ([`crate::Spline`]).
//!
//! ## Effects
//!
//! | effect | meaning |
//! |---|---|
//! | `gravity(gx, gy, gz);` | uniform gravity, world axes (constants and parameters) |
//! | `spring(a, b, k = …, l0 = …);` | point-to-point spring between points or body origins (`ground` is the world origin); `c = …` adds a damper |
//! | `spring(a, b, k = …, l0 = …, preload = F0);` | tension F0 + k (l − l0) (F0 > 0 pulls the ends together at the rest length); potential F0 (l − l0) + ½ k (l − l0)² |
//! | `spring(a, b, k = …, l0 = …, axis = x);` | a linear spring along a fixed world direction (`x`, `y`, `z` or a unit `(nx, ny, nz)`): its length is the signed distance along the axis, linear for any motion (1-D models) |
//! | `damper(a, b, c = …);` | point-to-point linear damper |
//! | `damper(a, b, c = …, axis = x);` | a linear damper along a fixed world direction |
//! | `force(p, (fx, fy, fz));` | a force at a point, world axes; `frame = body` for that body's axes |
//! | `torque(b, (mx, my, mz));` | a torque on a body, world axes; `frame = body`, `relative_to = other` (reaction on `other`) |
//! | `torque(b, axis = z, value, relative_to = other);` | a torque about one of `b`'s axes, reaction on `other` |
//! | `generalized_force(q[i], value);` | a generalised force on a coordinate |
//! | `contact(p, k = …, c = …, mu = …);` | penalty contact of a point or body origin with the ground plane z = 0 (below) |
//! | `contact(p, k = …, plane = y, offset = h0);` | with the fixed plane n·x = h0: `plane` is its unit normal pointing out of the ground, `x`, `y`, `z` (default), `-z`, … or `(nx, ny, nz)`; `offset` default 0 |
//! | `contact(body, sphere = r, k = …, …);` | a sphere of radius r centred at the body's origin (or at a point) |
//! | `contact(p, ellipsoid = (a, b, c), k = …, …);` | an ellipsoid centred at a point or body origin, semi-axes a, b, c along the axes of its body (or frame) |
//! | `contact(p, k = …, exponent = 1.5, dissipation = d, …);` | Hunt–Crossley normal force k δ^e (1 + d δ̇) instead of the linear k δ (below) |
//! | `rotational_spring(A, B, axis = z, k = …, angle0 = θ0);` | a linear rotational spring between two bodies or frames (either may be `ground`) about an axis (`x`, `y`, `z` or a unit `(nx, ny, nz)`, in A's axes): the torque −k (θ − θ0) about the axis on B and the opposite on A, θ the angle of B relative to A about it (below); potential ½ k (θ − θ0)²; `angle0` default 0; `c = …` adds a damper |
//! | `rotational_damper(A, B, axis = z, c = …);` | the torque −c θ̇ about the axis on B, the opposite on A |
//! | `bushing(A, B, k = (kx, ky, kz), kr = (…), c = (…), cr = (…));` | six-axis linear spring–damper between the origins and axes of two bodies or frames (either may be `ground`), coefficients along A's axes; one value sets all three axes; each of `k kr c cr` defaults to 0 (at least one) |
//!
//! Force and torque values may depend on `q`, `qd`, `t`, parameters and inputs `u[k]`; the
//! coefficients of springs, dampers, contacts and bushings are constants or parameters.
//! Gravity and springs are conservative (potential energy); the others count in `power()`;
//! contacts, bushings and rotational springs have both: their elastic parts are in the
//! potential, their damping and friction (whose power is never positive) in `power()`.
//!
//! **Contacts** are penalty forces generated with the rest of the equations (so M, h, τ, exact
//! tangents, energy and power include them). With the penetration δ = h0 + r − n·x of the
//! point (or sphere centre) x, r = 0 for a point, and its rate δ̇ = −n·v:
//!
//! - normal force F_n = step(δ)·pos(k δ + c δ̇) along n: zero out of contact, and the damping
//!   never pulls (non-adhesive);
//! - friction F_t = −μ F_n v_t / sqrt(|v_t|² + eps²), regularised Coulomb with v_t the
//!   tangential velocity of the contact point x − r n (for a sphere it includes ω × (−r n));
//!   `mu` default 0, `eps` default 1e-4 m/s (below it, friction is viscous);
//! - potential ½ k pos(δ)², the potential of the elastic part k pos(δ) (a contact without
//!   `c` and `mu` is conservative: its normal force is k pos(δ)).
//!
//! An **ellipsoid** with semi-axes D = diag(a, b, c) along its body's axes R touches the plane
//! at its support point along −n, x − R D² m / s with m = Rᵀ n and s = sqrt(mᵀ D² m), computed
//! in closed form in the generated code: δ = h0 − n·x + s, and the normal force and friction
//! act at that point (whose velocity has n·v = −δ̇ exactly, so the energy identity holds).
//! Equal semi-axes give the sphere. The **Hunt–Crossley** law replaces the linear spring by
//! k pos(δ)^e (1 + d δ̇): `exponent = e` (a number ≥ 1; 1.5 is Hertz's law for curved
//! surfaces, k then in N/m^1.5) and `dissipation = d` ≥ 0 (s/m; Hunt and Crossley's
//! d = 3α/2 with α from the coefficient of restitution, e ≈ 1 − α v at impact speed v), with
//! potential k pos(δ)^(e+1)/(e + 1); `c` still adds c δ̇, and the force never pulls:
//! F_n = step(δ)·pos(k pos(δ)^e (1 + d δ̇) + c δ̇).
//!
//! `k` is required and positive; `c` ≥ 0 (default 0), `mu` ≥ 0, `eps` > 0, `sphere` > 0,
//! semi-axes > 0, `dissipation` ≥ 0. A point contact applies no moment about the point; a
//! sphere or an ellipsoid with friction rolls. At first
//! touch the normal force jumps to c δ̇ (integrators with error control take small steps
//! there); c ≈ 2 ζ √(k m) gives a damping ratio ζ for a mass m on the contact.
//!
//! A contact meets one plane. Terrain of the ground and boxes on it is described in Rust
//! ([`crate::terrain`]): a [`crate::terrain::Terrain`] applies the same law to points and to
//! ellipsoids on bodies from an [`crate::Efforts`] part, through each face's support point.
//!
//! **Bushings**: with d = p_B − p_A, Δp = R_Aᵀ d, Δv = R_Aᵀ (v_B − v_A − ω_A × d) (B's origin
//! relative to the point of A it coincides with, in A's axes), R = R_Aᵀ R_B,
//! θ = ½ (R₃₂ − R₂₃, R₁₃ − R₃₁, R₂₁ − R₁₂) (the rotation vector of B relative to A for small
//! angles, as in `align`) and Ω = R_Aᵀ (ω_B − ω_A), B receives the force −K Δp − C Δv at its
//! origin and the torque −Eᵀ K_r θ − C_r Ω (A's axes), A the opposite force at the same point
//! and the opposite torque. E = ½ (tr R · I − R) makes the elastic torque the exact gradient
//! of the potential ½ Δpᵀ K Δp + ½ θᵀ K_r θ; it equals −K_r θ to first order in the angle.
//! Keep relative rotations well below 90°.
//!
//! ```
//! mbs::multibody! {
//!     /// A ball on a table, tied to a post by a preloaded spring and a bushing.
//!     model Table {
//!         param k = 1e5; param m = 1.0;
//!         dof x = 0.0; dof y = 0.0; dof z = 0.1; dof a = 0.0;
//!         body ball { mass = m; inertia = (0.004, 0.004, 0.004); }
//!         body post { mass = 0.5; inertia = (0.01, 0.01, 0.01); }
//!         TOG[ball] = Tdisp(x, y, z) * Trotz(a);
//!         TOG[post] = Tdisp(1, 0, 0.5);
//!         gravity(0, 0, -9.81);
//!         contact(ball, sphere = 0.1, k = k, c = 2 * sqrt(k * m), mu = 0.4);
//!         spring(ball, post, k = 20, l0 = 0.8, preload = 5);
//!         bushing(ground, ball, kr = (0, 0, 2), cr = 0.1);
//!     }
//! }
//! use mbs::Model;
//! let model = Table::default();
//! let (mut m, mut h) = ([0.0; 16], [0.0; 4]);
//! // 1 mm deep, the contact pushes up with k δ = 100 N (less the weight, plus the spring)
//! model.dynamics(0.0, &[0.0, 0.0, 0.099, 0.0], &[0.0; 4], &[], &mut m, &mut h);
//! assert!(h[2] > 90.0 && h[2] < 100.0);
//! ```
//!
//! **Rotational springs** act about one axis n (in A's axes) with the angle θ of B relative
//! to A about it. When every rotation between A and B in the tree (from each up to the pose
//! they share) is a `Trot…` about ±n — a joint, as in `TOG[B] = TOG[A] * Tdisp(…) *
//! Trotz(q[1]) * …` — θ is the sum of those rotations' angles, here `q[1]`: no trigonometry,
//! and the spring costs what `generalized_force(q[1], -k * (q[1] - θ0) - c * qd[1])` costs
//! (a chain of 8 bars with one at each joint: 234 flops for h either way). Otherwise θ is
//! read from the relative rotation R = R_Aᵀ R_B as atan2(n·vee(R − Rᵀ), tr R − nᵀ R n), the
//! angle of R when it is a rotation about n (and its twist about n when it is not), in
//! (−π, π]. Either way the load is the generalised force −(k (θ − θ0) + c θ̇) ∂θ/∂q, the
//! exact gradient of the potential ½ k (θ − θ0)² plus the damping, which is the torque pair
//! about n when B turns about n relative to A; the damper's power is −c θ̇².
//!
//! It differs from `torque(B, axis = z, value, relative_to = A)`, whose value is any
//! expression (`-k * q[1]`) with no potential: `energy()` misses its elastic energy and
//! `power()` counts its work; and from the bushing's `kr`, a stiffness on all three axes
//! whose angle is ½ vee(R − Rᵀ) (the sine of the angle for a single rotation), for small
//! relative rotations, with the translations held too.
//!
//! ```
//! mbs::multibody! {
//!     /// A double pendulum with a torsion spring at each joint and a damper at the elbow.
//!     model Sprung {
//!         param k = 5.0; param l = 1.0;
//!         dof q[0] = 0.5; dof q[1] = 0.0;
//!         body bar1 { mass = 1.0; inertia_z = l * l / 12; }
//!         body bar2 { mass = 1.0; inertia_z = l * l / 12; }
//!         mass tip on bar2 at (0, -l/2, 0) = 0.2;
//!         TOG[bar1] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
//!         TOG[bar2] = TOG[bar1] * Tdisp(0, -l/2, 0) * Trotz(q[1]) * Tdisp(0, -l/2, 0);
//!         rotational_spring(ground, bar1, axis = z, k = k, angle0 = 0.1);
//!         rotational_spring(bar1, bar2, axis = z, k = k, c = 0.2);
//!     }
//! }
//! use mbs::Model;
//! let model = Sprung::default();
//! let (mut m, mut h) = ([0.0; 4], [0.0; 2]);
//! model.dynamics(0.0, &[0.5, 0.3], &[0.0, 1.0], &[], &mut m, &mut h);
//! // on q[1], the elbow's spring and damper: −k q1 − c q̇1 (no centrifugal term there)
//! assert!((h[1] - (-5.0 * 0.3 - 0.2 * 1.0)).abs() < 1e-12);
//! let e = model.energy(0.0, &[0.5, 0.3], &[0.0, 0.0]);
//! assert!((e.potential - 0.5 * 5.0 * (0.4f64.powi(2) + 0.3f64.powi(2))).abs() < 1e-12);
//! ```
//!
//! ## Constraints
//!
//! With constraints the equations are `M qdd = h + Bᵀλ`, `Φ(q, t) = 0`, `B = ∂Φ/∂q`; the model
//! also provides Φ, B, ∂Φ/∂t, γ (with `B qdd = γ`) and ∂(Bᵀλ)/∂q, generated from the same
//! expressions. A crank–slider closed at its pin:
//!
//! ```
//! mbs::multibody! {
//!     model SliderCrank {
//!         dof theta = 0.0, qd = 10.0, independent; dof phi = 0.0; dof s = 0.4;
//!         body crank { mass = 0.5; inertia = (0, 0.5 * 0.01 / 12, 0.5 * 0.01 / 12); }
//!         body rod { mass = 1.0; inertia = (0, 0.09 / 12, 0.09 / 12); }
//!         body slider { mass = 2.0; }
//!         point crank_tip on crank at (0.05, 0, 0);
//!         point rod_end on rod at (0.15, 0, 0);
//!         TOG[crank] = Trotz(theta) * Tdisp(0.05, 0, 0);
//!         TOG[rod] = TOG[crank] * Tdisp(0.05, 0, 0) * Trotz(phi) * Tdisp(0.15, 0, 0);
//!         TOG[slider] = Tdisp(s, 0, 0);
//!         constraint pin: coincide(rod_end, slider, along = [x, y]);
//!     }
//! }
//! use mbs::Model;
//! let (model, mut phi) = (SliderCrank::default(), [1.0; 2]);
//! model.constraints(0.0, &[0.0, 0.0, 0.4], &mut phi);
//! assert!(phi.iter().all(|p| p.abs() < 1e-12));
//! ```
//!
//! | constraint | equations |
//! |---|---|
//! | `constraint NAME = expr;` | one scalar equation `expr = 0` in `q` and `t` |
//! | `constraint NAME: coincide(a, b);` | points (or body origins, `ground`) `a` and `b` coincide: 3 equations, world axes |
//! | `… coincide(a, b, along = [x, y]);` | only along the listed axes; `frame = body` for that body's axes |
//! | `constraint NAME: align(A, B);` | bodies `A` and `B` keep their relative orientation (3 equations) |
//! | `… align(A, B, about = [z]);` | only the listed rotations: each equation is the antisymmetric part of `R_Aᵀ R_B` about that axis (the sine of the relative angle for a single rotation), so keep the start within ±90° of aligned |
//!
//! `dof …, independent` marks the coordinates kept when the initial state is assembled (and
//! preferred as independent coordinates by partitioning). How a run treats the constraints —
//! at index 3, by projection, Baumgarte or coordinate partitioning — is an option of the
//! run: [`ConstraintMethod`](crate::ConstraintMethod).
//!
//! ## Shapes
//!
//! `shape` statements say how a body looks in the animations ([`anim`](crate::anim), an HTML
//! page, and [`gltf`](crate::gltf), a glTF 2.0 file); they change nothing in the equations.
//! Positions and sizes are in the axes of the body (origin at G) or frame they are drawn with,
//! or of the world for `ground`; a body may have several shapes.
//!
//! | shape | what |
//! |---|---|
//! | `shape B: box(lx, ly, lz);` | a box with sides lx, ly, lz along B's x, y, z, centred at B's origin |
//! | `shape B: cylinder(radius, length, axis = y);` | a cylinder along B's `x`, `y` or `z` (default `z`) |
//! | `shape B: sphere(radius);` | a sphere |
//! | `shape B: line(from = (x, y, z), to = (x, y, z));` | a segment between two points of B (a rod, a cable) |
//! | `…, at = (x, y, z)` | the centre of a box, cylinder or sphere (default the origin) |
//! | `…, color = "#rrggbb"` | its colour (default one per body; grey on the ground) |
//!
//! Their values are constants: numbers and parameters, taken **at their default values** when
//! the model is compiled (a shape does not follow a parameter changed at run time). Sizes
//! must be positive and a line's ends distinct. A body without `shape` is drawn as its
//! *equivalent box*: the box of the same mass and principal moments of inertia (sides
//! a² = 6 (I_y + I_z − I_x)/m along the principal axes), its thin sides at least 4 % of its
//! longest so that a slender body is a bar; a point mass is a sphere of water's density. A
//! massless frame without `shape` is not drawn. [`ModelInfo::shapes`](crate::ModelInfo)
//! lists the declared shapes then these defaults ([`ShapeInfo`](crate::ShapeInfo)).
//!
//! ```
//! mbs::multibody! {
//!     /// A pendulum on a cart, drawn.
//!     model Crane {
//!         param l = 0.8;
//!         dof x = 0.0; dof theta = 0.3;
//!         body cart { mass = 2.0; inertia = (0.01, 0.03, 0.03); }
//!         body bob { mass = 1.0; inertia = (0.004, 0.004, 0.004); }
//!         TOG[cart] = Tdisp(x, 0, 0);
//!         TOG[bob] = TOG[cart] * Trotx(theta) * Tdisp(0, 0, -l);
//!         shape cart: box(0.4, 0.2, 0.1, color = "#3366cc");
//!         shape cart: cylinder(0.05, 0.25, axis = y, at = (0.15, 0, -0.05));
//!         shape bob: sphere(0.08);
//!         shape bob: line(from = (0, 0, 0), to = (0, 0, l));
//!         shape ground: box(4, 0.05, 0.02, at = (0, 0, -0.06));
//!         gravity(0, 0, -9.81);
//!     }
//! }
//! use mbs::Model;
//! let info = Crane::default().info();
//! assert_eq!(info.shapes.len(), 5);
//! assert_eq!(info.shapes[2].kind, mbs::ShapeKind::Sphere { radius: 0.08 });
//! ```
//!
//! Simulate with `Options { frames: true, .. }` to record the poses, then
//! `mbs::anim::write_html(Path::new("crane.html"), model.info(), &trajectory)` (an HTML page,
//! feature `anim`) or `mbs::gltf::write_gltf(Path::new("crane.gltf"), model.info(),
//! &trajectory)` (a glTF file, feature `gltf`); both take a `&std::path::Path`.
//!
//! ## Repetition and parts
//!
//! | statement | meaning |
//! |---|---|
//! | `for i in 0..n { … }` | the statements once for each integer `i` from 0 to n − 1 (`0..=n` includes n); at model level and inside `effect` blocks; nestable |
//! | `body bar[i] { … }`, `dof b[i]`, `point tip[i] on bar[i] at …`, `param k[i] = …` | indexed names: the index is a constant integer expression (`i`, `i - 1`, `2 * i + 1`, `i / 2`, `i % 2`: integer arithmetic) |
//! | `TOG[bar[i]] = TOG[bar[i-1]] * …;`, `q[b[i]]`, `qd[b[i]]` | indexed names wherever names go |
//! | `q[2 * i + 1]`, `qd[i + 1]`, `u[i]` | the coordinate or input of that number (integer arithmetic, as in indexed names) |
//! | `Tdisp(i * l, 0, 0)` | elsewhere the loop variable is a number |
//! | `part Leg(k, hx, hy) { … }` | a template of statements, declared at model level (above or below its instances); its name starts with an uppercase letter |
//! | `Leg(0, 0.4, 0.3);` | an instance: the part's statements with each argument replaced by the tokens given for it |
//!
//! Loops and parts are unrolled before the model is checked, by substituting tokens: the
//! statements they produce are exactly those one would write out, so the generated code is
//! the same. The range of a loop is made of integers, loop variables and integer part
//! arguments (not parameters, which change at run time). A part's arguments may be integers
//! (indices; integer arithmetic that does not divide, `3 / 2`, is the number 1.5 where a
//! number goes, as the statement written out would be), scalar expressions (`0.4`, `-l / 2`), transform products (a mounting
//! transform, `TOG[base] * Trotz(PI)`, as the start of a product) and names (`Leg(0, base)`);
//! an argument of several tokens is substituted in parentheses. Parts may instantiate other
//! parts and contain loops.
//!
//! Names: loop variables and part arguments are local (they replace every identifier of that
//! name in their body, except argument names before `=` such as `k = …` in `contact(…)`; a
//! part's statements see its arguments, not the loop variables around the instance, so pass
//! them: `for i in 0..6 { Leg(i, …); }`);
//! every name a part declares is a name of the model, so an instance keeps its names apart
//! by indexing them with an argument (`body thigh[k]`). `thigh[3]` is how an indexed name
//! reads everywhere: in messages, `mbs expand`, [`ModelInfo`](crate::ModelInfo)'s coordinate,
//! body and point names, the CSV columns and the animations' node names. Where a name must
//! be a Rust identifier, the brackets become underscores: `param k[3]` is the field `k_3` of
//! the parameter struct (and is set by that name); a scene, whose name is a type, cannot be
//! indexed. An index is never negative (`bar[i - 1]` at i = 0 is an error at the template,
//! naming the instance); an index that no statement declares (`bar[40]` in a chain of 40)
//! is an unknown name, with the indices that exist.
//!
//! An error inside a loop or a part points at the template's tokens and says which instance
//! (``…; in `for i in 1..5`, i = 4``, `…; in part Leg, instance 3 (k = 2, hx = 0, hy = 0.3)`;
//! nested ones are listed outermost first); an error that several instances repeat word for
//! word is reported once, at the first. Mistakes of the statements themselves: a range that
//! is not made of constant integers, an index that is not a constant integer or is negative,
//! a wrong number of arguments to a part, an unknown part (with the closest name), a part
//! declared inside a loop, an effect or another part.
//!
//! ```
//! mbs::multibody! {
//!     /// A chain of 10 bars, a torsional spring in every joint, and two legs on a frame.
//!     model Repeated {
//!         param l = 0.5; param m = 1.0; param k = 50.0;
//!         for i in 0..10 {
//!             dof q[i] = 0.1;
//!             body bar[i] { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
//!         }
//!         TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
//!         for i in 1..10 {
//!             TOG[bar[i]] = TOG[bar[i-1]] * Tdisp(0, -l/2, 0) * Trotz(q[i]) * Tdisp(0, -l/2, 0);
//!             torque(bar[i], relative_to = bar[i-1], axis = z, -k * q[i]);
//!         }
//!         point tip on bar[9] at (0, -l/2, 0);
//!
//!         part Leg(j, mount, side) {
//!             dof hip[j] = 0.2 * side;
//!             body thigh[j] { mass = 1.0; inertia = (0.01, 0.01, 0.002); }
//!             TOG[thigh[j]] = mount * Tdisp(0, 0.1 * side, 0) * Trotx(hip[j]) * Tdisp(0, 0, -0.2);
//!             point foot[j] on thigh[j] at (0, 0, -0.2);
//!         }
//!         frame hips;
//!         TOG[hips] = Tdisp(3, 0, 1);
//!         Leg(0, TOG[hips], 1);
//!         Leg(1, TOG[hips], -1);
//!         effect stance { for j in 0..2 { contact(foot[j], k = 1e4, c = 100); } }
//!         gravity(0, -9.81, 0);
//!     }
//! }
//! use mbs::Model;
//! let info = Repeated::default().info();
//! assert_eq!(info.frames[9], "bar[9]");
//! assert_eq!(&info.dofs[10..], ["hip[0]", "hip[1]"]);
//! assert_eq!(info.points, ["tip", "foot[0]", "foot[1]"]);
//! ```
//!
//! ## Importing URDF
//!
//! `mbs import urdf robot.urdf [--floating-base] > robot.rs` (feature `urdf`; in Rust
//! [`urdf::import`](crate::urdf::import)) writes a robot's URDF description as a `multibody!`
//! block, a starting point to edit (effects, scenes, shapes):
//!
//! | URDF | `multibody!` |
//! |---|---|
//! | the root link | the `ground` (its mass does not move: a comment says so); with `--floating-base` ([`ImportOptions`](crate::urdf::ImportOptions)) a body on a `floating` joint `floating_base` (a drone, a legged robot) |
//! | `<link>` with `<inertial>` | `body`; TOG at the centre of mass (`<inertial><origin xyz>`), axes parallel to the link frame; `param`s `{link}_m`, `{link}_cx`…, `{link}_ixx`… (an `<inertial><origin rpy>` is rotated into those axes); when other links hang from the link, a `frame {link}_frame` at the joint carries them |
//! | `<link>` without mass | `frame` at the link frame |
//! | `<joint><origin xyz rpy>` | `Tdisp({joint}_dx, {joint}_dy, {joint}_dz) * Trotz(yaw) * Troty(pitch) * Trotx(roll)` (URDF's R = Rz·Ry·Rx) |
//! | `revolute`, `continuous` | `dof {joint}` (limits, effort and velocity in a comment; starts at 0, or the nearer limit), then `Trotx/y/z({joint})` about a coordinate axis (`Trotz(-{joint})` for −z), `Trotn(nx, ny, nz, {joint})` about another |
//! | `prismatic` | `Tdisp` along the axis |
//! | `fixed` | the child's mass and inertia merged into its parent's (parallel axes), the joint's origin in numbers (the merge used them); a massless child stays a `frame` |
//! | `floating` | `dof {joint}_x, _y, _z, _roll, _pitch, _yaw`: `Tdisp(x, y, z) * Trotz(yaw) * Troty(pitch) * Trotx(roll)` (singular at pitch = ±π/2) |
//! | `planar` | `dof {joint}_x, _y, _theta`: two translations in the plane normal to the axis (the basis in a comment), then the rotation about it |
//! | `<mimic joint multiplier offset>` | no coordinate: the joint turns by `multiplier * leader + offset` |
//! | `<dynamics damping friction>` | `param {joint}_damping`, `{joint}_friction`; `generalized_force({joint}, -{joint}_damping * qd[{joint}])` in `effect joint_damping`, `generalized_force({joint}, -{joint}_friction * tanh(qd[{joint}] / joint_friction_eps))` in `effect joint_friction` (eps 0.01 rad/s or m/s); a mimic joint's on its leader, times the multiplier; not applied to floating and planar joints (a comment says so) |
//! | `<visual>` box, cylinder, sphere | `shape` (`color` from its material); a mesh, or a box or cylinder turned off the link's axes, is a comment |
//! | — | `param g = 9.81;` and `gravity(0, 0, -g);` (z up, as in ROS) |
//!
//! ```text
//! mbs::multibody! {
//!     /// The `pendulum` robot, imported from its URDF description.
//!     pub model Pendulum {
//!         param g = 9.81;
//!         // link `rod`: mass (kg), centre of mass in the link frame (m), inertia about it (kg·m²)
//!         param rod_m = 1.0;
//!         param rod_cz = -0.5;
//!         param rod_ixx = 0.084;
//!         param rod_iyy = 0.084;
//!         param rod_izz = 0.001;
//!         // joint origins in the parent link frame (m)
//!         param hinge_dz = 2.0;
//!         dof hinge = 0.0; // continuous
//!         body rod { mass = rod_m; inertia = (rod_ixx, rod_iyy, rod_izz); }
//!         TOG[rod] = Tdisp(0, 0, hinge_dz) * Troty(hinge) * Tdisp(0, 0, rod_cz);
//!         shape rod: cylinder(0.02, 1.0, axis = z);
//!         gravity(0, 0, -g);
//!     }
//! }
//! ```
//!
//! is what this description gives:
//!
//! ```
//! # #[cfg(feature = "urdf")] {
//! let urdf = r#"<robot name="pendulum">
//!   <link name="base"/>
//!   <link name="rod">
//!     <inertial>
//!       <origin xyz="0 0 -0.5"/>
//!       <mass value="1"/>
//!       <inertia ixx="0.084" iyy="0.084" izz="0.001"/>
//!     </inertial>
//!     <visual>
//!       <origin xyz="0 0 -0.5"/>
//!       <geometry><cylinder radius="0.02" length="1"/></geometry>
//!     </visual>
//!   </link>
//!   <joint name="hinge" type="continuous">
//!     <parent link="base"/>
//!     <child link="rod"/>
//!     <origin xyz="0 0 2"/>
//!     <axis xyz="0 1 0"/>
//!   </joint>
//! </robot>"#;
//! let model = mbs::urdf::import(urdf).unwrap().model;
//! assert!(model.contains("TOG[rod] = Tdisp(0, 0, hinge_dz) * Troty(hinge) * Tdisp(0, 0, rod_cz);"));
//! assert!(model.contains("shape rod: cylinder(0.02, 1.0, axis = z);"));
//! // a mistake names the joint or link and the fix
//! let bad = urdf.replace(r#"<parent link="base"/>"#, r#"<parent link="bse"/>"#);
//! assert_eq!(
//!     mbs::urdf::import(&bad).unwrap_err().to_string(),
//!     "joint `hinge`: its parent link `bse` is not a `<link>` of the robot; did you mean `base`?"
//! );
//! # }
//! ```
//!
//! Bad descriptions are [`UrdfError`](crate::urdf::UrdfError)s, never a panic: XML that is not
//! well-formed, a missing element or attribute (with its line), a number that does not parse,
//! two links or joints of one name, a joint naming an unknown link, a link with two parent
//! joints, a cycle, none or several root links, a negative mass, a body's inertia that no rigid
//! body has (a negative principal moment, or one larger than the sum of the other two: what
//! `multibody!` refuses; checked on the sum with the links fixed to it, not on the ground's
//! links), a joint type other than the six above, an axis of zero length, a
//! mimic of an unknown, fixed or mimicking joint, a joint that moves no mass (M would be
//! singular), a robot without a moving joint. `examples/urdf.rs` imports a robot, prints its
//! op counts, then builds and simulates it.
//!
//! ## Errors
//!
//! Every mistake is a compile error on the offending tokens, naming the construct and the
//! fix, for example:
//!
//! ```text
//! error: unknown body `uper_arm`; did you mean `upper_arm`?
//! error: coordinate `q[2]` moves no body with mass, so the mass matrix would be singular: …
//! error: the mass of body `arm` must be positive, it is -1: …
//! error: unknown body `bar[4]`; `bar[…]` is declared with the indices 0 to 3; in `for i in 1..5`, i = 4
//! ```
//!
//! Some of them:
//!
//! | mistake | message |
//! |---|---|
//! | `param u = 1.0;` (or a body, coordinate, … named `t q qd qdd u PI E TAU ground TOG`) | "`u` is reserved for the inputs u\[k\]: give this parameter another name", once: its uses are not reported again |
//! | `TOG[a] = TOG[b] * …; TOG[b] = TOG[a] * …;` | "the poses form a cycle, `a → b → a`: each starts from the next, so none is ever placed; …" |
//! | `Tdisp(0, -sqrt(-1.0), 0)`, `ln(0)`, `asin(2)`, `exp(1000)`, `1e400` | "`sqrt(-1.0)` is NaN (not a number): an argument is outside the domain of the function or operation, …; correct the constant", on those tokens: constants fold when the model is compiled (`1/0`: "division by zero") |
//! | `body arm { mass = 1.0; inertia = (…); inertia_z = 0.1; }` | "body `arm` has its inertia twice: give either `inertia = (…);` or one moment `inertia_z = …;`" |
//! | `mass tip on ground at (0, 0, 0) = 0.5;` | "a mass on the ground never moves, so it changes nothing: put `tip` on a body" |
//! | `rotational_spring(ground, bar, k = k);` | "a rotational spring needs the axis it turns about, in the axes of A: add `axis = z` …" |
//! | `TOG[bsae]` | "unknown body `bsae`; did you mean `base`?": a swap of two adjacent letters counts as one edit, like a letter added, removed or replaced |
//!
//! All the mistakes of a model are reported at once. The macro still emits placeholder types
//! (the parameter struct with its fields, the model types with `new` and the
//! [`Model`](crate::Model) trait), so the code using them does not fail in cascade. Each
//! message has a compile-fail case under `compile-fail/tests/ui/`.
//!
//! ## Reading the generated code
//!
//! `mbs expand FILE.rs [--model NAME] [--scene S]` prints exactly what the macro emits,
//! pretty-printed, with a table of operations per generated function; below a method written
//! as a table of operations (`option tangents = table;`) it lists the operations one a line
//! as comments (`// s14 = p_k * s12 + s9`, `// k[3] = s14`). It reads the blocks of
//! `FILE.rs` and of the files it includes, found as rustc finds them (`mod name;`: `name.rs`
//! or `name/mod.rs`, in a folder named after a file that is not a crate root or `mod.rs`;
//! `#[path = "…"] mod name;` relative to the file's folder), and of the modules of workspace
//! crates it names in `use` (`use mbs_models::hexapod;` reads that crate's `src/hexapod.rs`,
//! so `mbs expand examples/hexapod.rs` shows the hexapod). Every error is printed as
//! `file:line:col: message` after every model has been tried, and the exit status is then
//! non-zero; an unknown `--scene` is an error that lists the scenes:
//!
//! ```text
//! error: examples/legs.rs:7:24: model `Bad`: unknown body `bra`; did you mean `bar`?
//! error: no scene `Drivn` in model `Leg`: its scenes are `Passive` and `Driven`
//! ```
