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
//! | `let I = m*l*l/12;` | a named expression, substituted where used |
//! | `dof q[0] = PI/2;` | the next coordinate, with its initial value (default 0) |
//! | `dof knee = 0.2, qd = 1.0;` | a named coordinate with initial position and velocity; `knee`, `q[knee]`, `qd[knee]` refer to it |
//! | `input torque;` | the next input `u[k]`; `torque` or `u[k]` in effects |
//! | `body arm { mass = m; inertia = (Ixx, Iyy, Izz); }` | a body; its frame (TOG) is at its centre of gravity G |
//! | `inertia = (Ixx, Iyy, Izz, Ixy, Ixz, Iyz);` | full tensor about G in body axes; the entries are the tensor's (`Ixy = −∫xy dm`) |
//! | `body point_mass { mass = 2.0; }` | a point mass (zero inertia) |
//! | `frame sensor;` | a massless frame (a secondary frame) |
//! | `point tip on arm at (0, -l/2, 0);` | a point fixed on a body, frame or `ground`, in its axes |
//! | `TOG[arm] = …;` | the body's pose: a product of transforms (below) |
//! | `fn g5(x) = 0.1*sin(x);` | an inline function, differentiated symbolically |
//! | `extern fn g6 = [knee::g6, knee::g6_d, knee::g6_dd];` | a Rust function `f64 -> f64` and its successive derivatives |
//! | `effect name { … }` | a named group of effect statements |
//! | `gravity(0, -g, 0);` … outside an `effect` | an effect that is always on |
//! | `scene Swing = [gravity];` | a model type `{Model}Swing` with those effects (plus the always-on ones) |
//! | `constraint drive = crank - w * t;` | a scalar constraint Φ(q, t) = 0 (closed loops, driving constraints) |
//! | `constraint close: coincide(a, b, along = [x, y]);` | two points meet along world axes (default x, y, z), or the axes of `frame = body`: one constraint per axis, named `close.x`, `close.y` |
//! | `constraint hinge: align(A, B, about = [x, y]);` | frame B keeps its orientation relative to A about A's axes: `hinge.rx`, `hinge.ry` |
//! | `dof crank = PI/3, independent;` | kept at its value when a closed loop is assembled |
//! | `option tangents;` | also generate exact K_t = ∂τ/∂q and C_t = ∂τ/∂qd |
//! | `option formulation = recursive;` | force `recursive` or `virtual_power` (default: the cheaper by op count) |
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
//!
//! Arguments are expressions of `q`, `t` (rheonomic, imposed motion) and parameters, never of
//! velocities or inputs.
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
//! tan asin acos atan atan2(y, x) sinh cosh tanh exp ln sqrt abs sign powi(x, n) pow(x, y)`
//! (also as methods: `x.sin()`). `^` is not a power; write `powi(x, 2)`.
//!
//! ## Effects
//!
//! | effect | meaning |
//! |---|---|
//! | `gravity(gx, gy, gz);` | uniform gravity, world axes (constants and parameters) |
//! | `spring(a, b, k = …, l0 = …);` | point-to-point spring between points or body origins (`ground` is the world origin); `c = …` adds a damper |
//! | `spring(a, b, k = …, l0 = …, axis = x);` | a linear spring along a fixed world direction (`x`, `y`, `z` or a unit `(nx, ny, nz)`): its length is the signed distance along the axis, linear for any motion (1-D models) |
//! | `damper(a, b, c = …);` | point-to-point linear damper |
//! | `damper(a, b, c = …, axis = x);` | a linear damper along a fixed world direction |
//! | `force(p, (fx, fy, fz));` | a force at a point, world axes; `frame = body` for that body's axes |
//! | `torque(b, (mx, my, mz));` | a torque on a body, world axes; `frame = body`, `relative_to = other` (reaction on `other`) |
//! | `torque(b, axis = z, value, relative_to = other);` | a torque about one of `b`'s axes, reaction on `other` |
//! | `generalized_force(q[i], value);` | a generalised force on a coordinate |
//!
//! Force and torque values may depend on `q`, `qd`, `t`, parameters and inputs `u[k]`.
//! Gravity and springs are conservative (potential energy); the others count in `power()`.
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
//! ## Errors
//!
//! Every mistake is a compile error on the offending tokens, naming the construct and the
//! fix, for example:
//!
//! ```text
//! error: unknown body `uper_arm`; did you mean `upper_arm`?
//! error: coordinate `q[2]` moves no body with mass, so the mass matrix would be singular: …
//! error: the mass of body `arm` must be positive, it is -1: …
//! ```
//!
//! All the mistakes of a model are reported at once. The macro still emits placeholder types
//! (the parameter struct with its fields, the model types with `new` and the
//! [`Model`](crate::Model) trait), so the code using them does not fail in cascade. Each
//! message has a compile-fail case under `tests/ui/`.
//!
//! ## Reading the generated code
//!
//! `mbs expand FILE.rs [--model NAME] [--scene S]` prints exactly what the macro emits,
//! pretty-printed, with a table of operations per generated function.
