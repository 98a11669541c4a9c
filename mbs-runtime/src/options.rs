//! Options in: plain structs with documented defaults, validated before any work.

use crate::error::{Failure, short};
use serde::{Deserialize, Serialize};

/// Newmark's parameters β and γ (default: the trapezoidal rule β = ¼, γ = ½, unconditionally
/// stable, no numerical damping).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NewmarkParams {
    pub beta: f64,
    pub gamma: f64,
}

impl Default for NewmarkParams {
    fn default() -> Self {
        NewmarkParams {
            beta: 0.25,
            gamma: 0.5,
        }
    }
}

/// Hilber–Hughes–Taylor α ∈ [−1/3, 0] (default −0.05); β = (1 − α)²/4, γ = ½ − α.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HhtParams {
    pub alpha: f64,
}

impl Default for HhtParams {
    fn default() -> Self {
        HhtParams { alpha: -0.05 }
    }
}

/// Generalized-α (Chung & Hulbert 1993): α_m, α_f, β, γ; build it from the spectral radius at
/// infinite frequency with [`GenAlphaParams::from_rho_inf`] (default ρ∞ = 0.8).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GenAlphaParams {
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub beta: f64,
    pub gamma: f64,
    /// the ρ∞ it was built from (NaN when given by hand)
    pub rho_inf: f64,
}

impl GenAlphaParams {
    /// The second-order, unconditionally stable member with spectral radius ρ∞ ∈ [0, 1] at
    /// infinite frequency: α_m = (2ρ∞ − 1)/(ρ∞ + 1), α_f = ρ∞/(ρ∞ + 1), γ = ½ − α_m + α_f,
    /// β = ¼(1 − α_m + α_f)².
    pub fn from_rho_inf(rho_inf: f64) -> GenAlphaParams {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 - alpha_m + alpha_f;
        GenAlphaParams {
            alpha_m,
            alpha_f,
            beta: 0.25 * (gamma + 0.5) * (gamma + 0.5),
            gamma,
            rho_inf,
        }
    }
}

impl Default for GenAlphaParams {
    fn default() -> Self {
        GenAlphaParams::from_rho_inf(0.8)
    }
}

/// BDF of variable order up to `max_order` ∈ 1..=5 (default 5).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BdfParams {
    pub max_order: usize,
}

impl Default for BdfParams {
    fn default() -> Self {
        BdfParams { max_order: 5 }
    }
}

/// The integration schemes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Scheme {
    /// explicit Euler, order 1 (fixed step)
    ExplicitEuler,
    /// classical Runge–Kutta, order 4 (fixed step)
    Rk4,
    /// Runge–Kutta–Chebyshev, order 2, its stages from the fastest mode (adaptive or fixed
    /// step): explicit, for motions whose fast modes decay
    Rkc,
    /// Dormand–Prince 5(4) with dense output (adaptive or fixed step)
    Dopri5,
    /// Newmark (β, γ), second-order form, Newton on accelerations
    Newmark(NewmarkParams),
    /// Hilber–Hughes–Taylor α
    Hht(HhtParams),
    /// generalized-α (Chung & Hulbert 1993, Arnold & Brüls 2007 form)
    GenAlpha(GenAlphaParams),
    /// backward differentiation formulas, variable step and order
    Bdf(BdfParams),
    /// Radau IIA, 2 stages, order 3 (the seed's RKI 5/12)
    Radau3,
    /// Radau IIA, 3 stages, order 5 (RADAU5-like)
    Radau5,
    /// implicit midpoint rule, order 2, symmetric (fixed step)
    ImplicitMidpoint,
}

impl Scheme {
    /// Short name, as on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Scheme::ExplicitEuler => "euler",
            Scheme::Rk4 => "rk4",
            Scheme::Rkc => "rkc",
            Scheme::Dopri5 => "dopri5",
            Scheme::Newmark(_) => "newmark",
            Scheme::Hht(_) => "hht",
            Scheme::GenAlpha(_) => "gen-alpha",
            Scheme::Bdf(_) => "bdf",
            Scheme::Radau3 => "radau3",
            Scheme::Radau5 => "radau5",
            Scheme::ImplicitMidpoint => "midpoint",
        }
    }

    /// The scheme of a name (defaults for its parameters).
    pub fn from_name(name: &str) -> Option<Scheme> {
        Some(match name {
            "euler" => Scheme::ExplicitEuler,
            "rk4" => Scheme::Rk4,
            "rkc" => Scheme::Rkc,
            "dopri5" => Scheme::Dopri5,
            "newmark" => Scheme::Newmark(NewmarkParams::default()),
            "hht" => Scheme::Hht(HhtParams::default()),
            "gen-alpha" => Scheme::GenAlpha(GenAlphaParams::default()),
            "bdf" => Scheme::Bdf(BdfParams::default()),
            "radau3" => Scheme::Radau3,
            "radau5" => Scheme::Radau5,
            "midpoint" => Scheme::ImplicitMidpoint,
            _ => return None,
        })
    }

    /// Every scheme with default parameters.
    pub fn all() -> [Scheme; 11] {
        [
            "euler",
            "rk4",
            "rkc",
            "dopri5",
            "newmark",
            "hht",
            "gen-alpha",
            "bdf",
            "radau3",
            "radau5",
            "midpoint",
        ]
        .map(|n| Scheme::from_name(n).expect("known name"))
    }

    /// Classical order of accuracy.
    pub fn order(&self) -> usize {
        match self {
            Scheme::ExplicitEuler => 1,
            Scheme::Rk4 => 4,
            Scheme::Dopri5 => 5,
            Scheme::Newmark(p) => {
                if (p.gamma - 0.5).abs() < 1e-15 {
                    2
                } else {
                    1
                }
            }
            Scheme::Hht(_) | Scheme::GenAlpha(_) | Scheme::ImplicitMidpoint | Scheme::Rkc => 2,
            Scheme::Bdf(p) => p.max_order,
            Scheme::Radau3 => 3,
            Scheme::Radau5 => 5,
        }
    }

    /// Whether the scheme solves nonlinear equations (Newton) at each step.
    pub fn is_implicit(&self) -> bool {
        !matches!(
            self,
            Scheme::ExplicitEuler | Scheme::Rk4 | Scheme::Rkc | Scheme::Dopri5
        )
    }

    /// Spectral radius at infinite frequency ρ∞ of the Newmark family (1: no numerical
    /// damping; `None` for other schemes).
    pub fn spectral_radius_at_infinity(&self) -> Option<f64> {
        match *self {
            Scheme::Newmark(p) if (p.gamma - 0.5).abs() < 1e-15 => Some(1.0),
            Scheme::Newmark(_) => Some(f64::NAN),
            Scheme::Hht(p) => Some((1.0 + p.alpha) / (1.0 - p.alpha)),
            Scheme::GenAlpha(p)
                if (p.alpha_m - 0.5).abs() < 1e-12 && (p.alpha_f - 0.5).abs() < 1e-12 =>
            {
                Some(1.0)
            }
            Scheme::GenAlpha(p) => Some(p.rho_inf),
            _ => None,
        }
    }

    /// Whether the scheme solves constrained models at index 3 ([`ConstraintMethod::Index3`]).
    pub fn solves_index3(&self) -> bool {
        matches!(
            self,
            Scheme::Newmark(_)
                | Scheme::Hht(_)
                | Scheme::GenAlpha(_)
                | Scheme::Radau3
                | Scheme::Radau5
        )
    }

    /// Whether the scheme solves constrained models in the stabilized index-2 form
    /// ([`ConstraintMethod::Index2`]).
    pub fn solves_index2(&self) -> bool {
        // the same schemes as index 3: the scheme itself solves for the multipliers
        self.solves_index3()
    }

    /// Whether the scheme can control its step by a local error estimate.
    pub fn is_adaptive(&self) -> bool {
        !matches!(
            self,
            Scheme::ExplicitEuler | Scheme::Rk4 | Scheme::ImplicitMidpoint
        )
    }
}

/// How the step is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum StepControl {
    /// constant step `h` (s); the last step is shortened to land on `t_end`
    Fixed { h: f64 },
    /// local error control: ‖err‖ ≤ 1 with weights atol + rtol·|y| per component;
    /// `h0` the first step (default: chosen from the initial state)
    Adaptive {
        rtol: f64,
        atol: f64,
        h0: Option<f64>,
    },
}

impl StepControl {
    /// The command line's convention: a fixed step `h` when given, else adaptive with `rtol`
    /// and `atol` (rtol/100 when not given).
    pub fn from_settings(h: Option<f64>, rtol: f64, atol: Option<f64>) -> StepControl {
        match h {
            Some(h) => StepControl::Fixed { h },
            None => StepControl::Adaptive {
                rtol,
                atol: atol.unwrap_or(rtol * 1e-2),
                h0: None,
            },
        }
    }
}

impl Default for StepControl {
    /// Adaptive, rtol 1e-6, atol 1e-8.
    fn default() -> Self {
        StepControl::Adaptive {
            rtol: 1e-6,
            atol: 1e-8,
            h0: None,
        }
    }
}

/// Where the trajectory is sampled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
pub enum Output {
    /// every accepted step (the default)
    #[default]
    Steps,
    /// every `dt` seconds from t0 (interpolated, of the scheme's order)
    Every { dt: f64 },
    /// at these times (sorted, within [t0, t_end]; interpolated)
    Times(Vec<f64>),
    /// only the final state
    Last,
}

/// How implicit schemes build their iteration matrix M + γ'·C_t + β'·K_t.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum IterationMatrix {
    /// exact tangents when the model was generated with `option tangents`, finite
    /// differences of τ otherwise (the default; `Stats` shows which evaluations were made)
    #[default]
    Auto,
    /// exact generated tangents (an error if the model has none)
    Exact,
    /// M alone: cheaper, converges for mild stiffness ("an approximate iteration matrix is
    /// sufficient"); stiff springs need the full matrix
    MassOnly,
    /// forward differences of τ, one evaluation per coordinate
    FiniteDifferences,
}

/// Newton iterations of implicit schemes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NewtonOptions {
    /// iterations per solve before the step is rejected and h reduced (default 7)
    pub max_iterations: usize,
    /// convergence when the predicted remaining correction of positions and velocities is
    /// below `tolerance_factor` times the step's error tolerance (adaptive) ...
    pub tolerance_factor: f64,
    /// ... or, for fixed steps, below ATOL' + RTOL·|…| with these (defaults 1e-10, 1e-10),
    /// where, for the Newmark family and the midpoint rule, ATOL' of positions, velocities and
    /// multipliers is the smaller of ATOL and RTOL times the largest value of that kind in the
    /// step: the iteration converges as far in any units (an ATOL in SI units alone is loose
    /// for a motion whose values are small in them); a correction that stalls within ATOL
    /// itself (values that are rounding errors, as at rest in an equilibrium) converges.
    /// Radau's weights use ATOL
    pub atol: f64,
    pub rtol: f64,
    /// reuse the factorised iteration matrix across iterations and steps while convergence
    /// is fast (modified Newton; default true)
    pub reuse: bool,
    /// Radau IIA: the contraction θ of Newton's iteration below which the iteration matrices
    /// are kept for the next step (RADAU5's THET). `None` (the default): [`COSTLY_KEEP_BELOW`]
    /// where they are costly, differences (of τ, or of the index-1 form of a closed loop) on
    /// a model of [`COSTLY_COORDINATES`] coordinates or more, 2n + 1 evaluations each, as
    /// RADAU5's documentation advises; RADAU5's [`RADAU5_KEEP_BELOW`] otherwise, which
    /// re-evaluates them after nearly every step that needed more than one iteration (on
    /// small models a stale matrix costs more than it saves). The figures: README, "Schemes"
    #[serde(default)]
    pub keep_below: Option<f64>,
}

/// RADAU5's THET, [`NewtonOptions::keep_below`] where the iteration matrices are cheap.
pub const RADAU5_KEEP_BELOW: f64 = 0.001;
/// [`NewtonOptions::keep_below`] where the iteration matrices are costly.
pub const COSTLY_KEEP_BELOW: f64 = 0.1;
/// The size from which iteration matrices by differences count as costly.
pub const COSTLY_COORDINATES: usize = 16;

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            max_iterations: 7,
            tolerance_factor: 0.03,
            atol: 1e-10,
            rtol: 1e-10,
            reuse: true,
            keep_below: None,
        }
    }
}

/// How a constrained model (`M qdd = h + Bᵀλ`, `Φ(q, t) = 0`) is integrated. Every method
/// starts from a consistent state (assembly, velocity projection, qdd₀ and λ₀ from the
/// index-1 equations) and records λ in the trajectory.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Default)]
#[non_exhaustive]
pub enum ConstraintMethod {
    /// `Index3` for the Newmark family (generalized-α, HHT, Newmark; `Index2` follows rtol in
    /// (q, qd) but costs more for the same digits: 3–14× on fastlink), except for its
    /// undamped members (ρ∞ = 1: Newmark's trapezoidal rule, generalized-α at ρ∞ = 1, HHT at
    /// α = 0), whose λ oscillates at index 3 and 2 and which may diverge there; `Projection`
    /// for every other scheme,
    /// Radau included: at index 3 Radau's λ is only of order s − 1 and its error control
    /// does not aim at it, while projection gives λ of the index-1 form at the accuracy of q
    /// and qd (in the stabilized index-2 form λ is of order s, and the run takes more steps
    /// and more work per step for errors in q and qd about as small) — the default
    #[default]
    Auto,
    /// the index-3 DAE solved directly: Φ(q₁) = 0 and the dynamics with λ₁ as unknowns
    /// (generalized-α, HHT, Newmark with the scaled iteration matrix of Bottasso, Dopico &
    /// Trainelli 2008; refused for the undamped members with adaptive steps), or at every
    /// stage with (A_i, Λ_i) as unknowns (radau3, radau5, as Hairer's RADAU5 solves index-3
    /// DAEs: positions of order 2s − 1, velocities s, λ s − 1; the error test counts velocity
    /// and λ errors by the positions they move in a step, h e_v + h² M_ii⁻¹(Bᵀe_λ)_i,
    /// `ErrorTest::PositionsScaledVelocities`; radau5 holds it at 3·rtol^(4/3), so that its
    /// velocities follow rtol from 1e-4 to 1e-8, radau3 at 3·rtol^1.5, alike)
    Index3,
    /// the stabilized index-2 form of Gear, Gupta & Leimkuhler (1985): Φ(q) = 0 and
    /// Φ̇ = B qd + Φ_t = 0 both enforced, the second by a multiplier μ that corrects the
    /// positions (q̇ = qd + B₀ᵀμ in Radau, B₀ = B at the start of the step, μ = 0 on the
    /// exact solution; q₁ += Bᵀν in the Newmark family, the stabilized index-2
    /// generalized-α of Arnold, Brüls & Cardona); velocities satisfy their constraints at
    /// every step, and the error test covers positions and velocities (radau3, radau5:
    /// q and qd of order 2s − 1, λ of order s, its error counted by the velocities
    /// h M_ii⁻¹(Bᵀe_λ)_i it moves in a step)
    Index2,
    /// the index-1 form (B qdd = γ, λ eliminated) with Baumgarte's stabilisation
    /// Φ̈ + 2αΦ̇ + β²Φ = 0 (α, β in 1/s; α = β = 0 is the plain index-1 form, which drifts);
    /// stops with `ConstraintDrift` when |Φ| exceeds `drift_tol`
    Baumgarte { alpha: f64, beta: f64 },
    /// the index-1 form, with q and qd projected onto Φ = 0 and Φ̇ = 0 (in the metric of M)
    /// after every accepted step
    Projection,
    /// coordinate partitioning (Wehage & Haug 1982): the scheme integrates an ODE in the
    /// independent coordinates; the dependent ones are solved from Φ = 0 and Φ̇ = 0 at every
    /// evaluation; the partition is chosen again (pivoting on B) when it becomes
    /// ill-conditioned
    Partitioning,
}

impl ConstraintMethod {
    /// Short name, as on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            ConstraintMethod::Auto => "auto",
            ConstraintMethod::Index3 => "index3",
            ConstraintMethod::Index2 => "index2",
            ConstraintMethod::Baumgarte { .. } => "baumgarte",
            ConstraintMethod::Projection => "projection",
            ConstraintMethod::Partitioning => "partitioning",
        }
    }

    /// The method of a name as on the command line: `auto`, `index3`, `index2`,
    /// `projection`, `partitioning` or `baumgarte:ALPHA,BETA`; the error says what is known.
    pub fn from_name(s: &str) -> Result<ConstraintMethod, String> {
        let bad = || {
            format!(
                "unknown constraint method `{s}`: use auto, index3, index2, projection, partitioning or baumgarte:ALPHA,BETA"
            )
        };
        Ok(match s {
            "auto" => ConstraintMethod::Auto,
            "index3" => ConstraintMethod::Index3,
            "index2" => ConstraintMethod::Index2,
            "projection" => ConstraintMethod::Projection,
            "partitioning" => ConstraintMethod::Partitioning,
            _ => {
                let rest = s.strip_prefix("baumgarte:").ok_or_else(bad)?;
                let (a, b) = rest.split_once(',').ok_or_else(bad)?;
                ConstraintMethod::Baumgarte {
                    alpha: a.trim().parse().map_err(|_| bad())?,
                    beta: b.trim().parse().map_err(|_| bad())?,
                }
            }
        })
    }
}

/// Settings for constrained models (ignored when the model has no constraints).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConstraintOptions {
    pub method: ConstraintMethod,
    /// |Φ_i| to reach when assembling, projecting, completing dependent coordinates and in
    /// the Newton iterations at index 3 and 2 (in the constraint's units, m or rad; default
    /// 1e-11; at index 2 also |Φ̇_i|, per unit of the largest velocity under the Newmark
    /// family). Where it is below what rounding leaves of Φ (100 ε of its largest terms) or
    /// of Φ̇, Newton closes to that instead: a mechanism in micrometres may ask for 1e-17 m,
    /// one of hundreds of kilometres gets what rounding allows.
    pub tolerance: f64,
    /// stop with `ConstraintDrift` when some |Φ_i| exceeds this after a step (default 1e-6)
    pub drift_tol: f64,
    /// Newton iterations for assembly, projection and completion (default 50)
    pub max_iterations: usize,
    /// index-3 Newmark family: scale the constraint rows of the iteration matrix by 1/β'
    /// (default true; false keeps the unscaled matrix whose condition grows as 1/h²); the
    /// index-3 Radau blocks are always scaled (by 1/(h²μ²))
    pub scaling: bool,
}

impl ConstraintOptions {
    /// Checks the tolerances and the iteration count.
    pub fn validate(&self) -> Result<(), Failure> {
        for (name, v) in [
            ("constraints.tolerance", self.tolerance),
            ("constraints.drift_tol", self.drift_tol),
        ] {
            if !(v > 0.0) || !v.is_finite() {
                return Err(invalid(name, v, "must be > 0 and finite"));
            }
        }
        if self.tolerance > self.drift_tol {
            return Err(invalid(
                "constraints.tolerance",
                self.tolerance,
                "exceeds constraints.drift_tol, at which a run stops: a closure left within the tolerance would stop it; take a tolerance below drift_tol",
            ));
        }
        if self.max_iterations == 0 {
            return Err(invalid("constraints.max_iterations", 0, "must be > 0"));
        }
        Ok(())
    }
}

impl Default for ConstraintOptions {
    fn default() -> Self {
        ConstraintOptions {
            method: ConstraintMethod::Auto,
            tolerance: 1e-11,
            drift_tol: 1e-6,
            max_iterations: 50,
            scaling: true,
        }
    }
}

/// Everything a simulation needs besides the model and the scheme.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Options {
    /// start time (s), default 0
    pub t0: f64,
    /// end time (s), default 1
    pub t_end: f64,
    /// initial q and qd (default: the model's declared initial state)
    pub q0: Option<Vec<f64>>,
    pub qd0: Option<Vec<f64>>,
    pub step: StepControl,
    pub output: Output,
    /// largest step (s); the default (infinity) means the whole span |t_end − t0|, as in
    /// Hairer's DOPRI5 and RADAU5 (see [`Options::h_max`])
    pub h_max: f64,
    /// smallest step of adaptive schemes before `StepTooSmall` (s), default
    /// 1e-12·max(1, |t|) at the current time t: the resolution of time, not a fraction of
    /// t_end (see [`Options::h_min_at`]); a fixed step is never judged by it
    pub h_min: Option<f64>,
    /// accepted plus rejected steps before `TooMuchWork` (default 1,000,000)
    pub max_steps: usize,
    pub newton: NewtonOptions,
    pub iteration_matrix: IterationMatrix,
    /// explicit fixed-step schemes (explicit Euler, RK4, DOPRI5 with a fixed step) estimate the
    /// largest eigenvalue of the dynamics (two extra evaluations every 16 steps, every 4 near
    /// the limit) and stop with `UnstableStep` when h·ρ leaves the scheme's stability region
    /// (default true). RKC estimates its modes whatever this says (its stages come from
    /// them); false lets it step on with its most stages where no stage count holds them.
    pub stability_check: bool,
    /// stop with `Failure::SingularConfiguration` when the coordinates approach a singular
    /// configuration (Euler angles at gimbal lock, joint axes lining up, a coordinate that
    /// stops moving mass): when a pivot of the mass matrix's factorisation falls below this
    /// fraction of its value at the start (default 1e-4; 0 disables). A Cholesky pivot L_jj²
    /// is the inertia of coordinate j that the coordinates before it cannot produce, a pivot
    /// of the generated forward dynamics (articulated bodies, LᵀDL) the one the coordinates
    /// after it cannot; each is compared with its own start value of the same kind, so
    /// metres and radians do not mix. Watched wherever M qdd = h is solved (the start, every
    /// evaluation of the explicit schemes and implicit midpoint, index-1 forms) and, for the
    /// other implicit schemes, at every iteration matrix that evaluates M
    /// (one Cholesky factorisation of M each, counted in `Stats::condition_checks`); the
    /// Newmark family and BDF with iteration matrices by finite differences of τ, which do not
    /// evaluate M, watch every accepted state instead (one evaluation and one Cholesky
    /// factorisation of M per accepted step). Healthy models stay far above 1e-4: over 20,000 random
    /// configurations the pivots stay above 1.5e-2 of their start values for chain16, chain24
    /// and arm3d_6, 8.9e-2 for the hexapod (pitch within ±1.3 rad), while a body on ZYX
    /// Euler angles crosses 1e-4 between 0.01 and 0.05 rad from gimbal lock (depending on
    /// the spread of its inertia). Closed loops are watched alike for change points and dead
    /// centres, where B = ∂Φ/∂q loses rank (`Failure::SingularLoop`): the Cholesky pivots of
    /// S = B M⁻¹ Bᵀ at every index-1 solve, and of B Bᵀ after every step of the index-3 and
    /// stabilized index-2 forms (one evaluation of B each, counted in `Stats::loop_checks`),
    /// against their start values
    #[serde(default = "default_singularity_tol")]
    pub singularity_tol: f64,
    /// re-centre the chart of a rotation joint (`Tball`, `Tfree`: ZYX angles a, b, c read in a
    /// chart the model holds) when |cos b| falls below this after an accepted step (default
    /// 0.5, b at ±60°; 0 never re-centres, and the joint stops at gimbal lock like any Euler
    /// angles): the chart moves to the joint's current rotation and its angles to zero,
    /// rates and accelerations mapped exactly, the scheme keeping its step (see
    /// [`crate::charts`]). Models without rotation joints ignore it
    #[serde(default = "default_chart_switch")]
    pub chart_switch: f64,
    /// record the poses of every body and frame at each output (default false)
    pub frames: bool,
    /// record kinetic and potential energy at each output (default true)
    pub energy: bool,
    /// how constraints are integrated (constrained models only)
    pub constraints: ConstraintOptions,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            t0: 0.0,
            t_end: 1.0,
            q0: None,
            qd0: None,
            step: StepControl::default(),
            output: Output::default(),
            h_max: f64::INFINITY,
            h_min: None,
            max_steps: 1_000_000,
            newton: NewtonOptions::default(),
            iteration_matrix: IterationMatrix::default(),
            stability_check: true,
            singularity_tol: default_singularity_tol(),
            chart_switch: default_chart_switch(),
            frames: false,
            energy: true,
            constraints: ConstraintOptions::default(),
        }
    }
}

fn default_singularity_tol() -> f64 {
    1e-4
}

fn default_chart_switch() -> f64 {
    0.5
}

fn invalid(name: &'static str, value: impl ToString, reason: &'static str) -> Failure {
    let mut value = value.to_string();
    // a number written out by `f64`'s Display (1e-300 as 0.000…1, 302 characters): short
    if value.len() > 15 && value.parse::<u64>().is_err() {
        if let Ok(x) = value.parse::<f64>() {
            value = short(x);
        }
    }
    Failure::InvalidOption {
        name,
        value,
        reason,
    }
}

impl Options {
    /// Fixed step `h` from 0 to `t_end`, every step recorded.
    pub fn fixed(t_end: f64, h: f64) -> Options {
        Options {
            t_end,
            step: StepControl::Fixed { h },
            ..Options::default()
        }
    }

    /// Adaptive steps with `rtol` (atol = rtol/100) from 0 to `t_end`.
    pub fn adaptive(t_end: f64, rtol: f64) -> Options {
        Options {
            t_end,
            step: StepControl::Adaptive {
                rtol,
                atol: rtol * 1e-2,
                h0: None,
            },
            ..Options::default()
        }
    }

    /// The smallest adaptive step allowed at the start.
    pub fn h_min(&self) -> f64 {
        self.h_min_at(self.t0)
    }

    /// The smallest adaptive step allowed at time `t`: the given `h_min`, or
    /// 1e-12·max(1, |t|) — some 4,500 rounding units of t, below which t + h no longer
    /// resolves the step. It follows t rather than t_end: a long run (t_end = 1e30) does not
    /// start with a floor of 1e18 s that the first step would be pushed up to.
    pub fn h_min_at(&self, t: f64) -> f64 {
        self.h_min.unwrap_or(1e-12 * t.abs().max(1.0))
    }

    /// The largest step: the given `h_max`, or by default the span |t_end − t0| (Hairer's
    /// DOPRI5 and RADAU5 take HMAX = XEND − X). Together with the first-step estimate
    /// (Hairer, Nørsett & Wanner) and a floor `h_min_at` that follows t, this makes the
    /// first step of a long run (t_end = 1e30) the one the dynamics ask for, not one pushed
    /// up to a fraction of t_end.
    pub fn h_max(&self) -> f64 {
        self.h_max
            .min((self.t_end - self.t0).abs())
            .max(f64::MIN_POSITIVE)
    }

    /// Checks every option against the scheme and the model's sizes.
    pub fn validate(&self, scheme: &Scheme, nq: usize, has_tangents: bool) -> Result<(), Failure> {
        let finite = |name: &'static str, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(invalid(name, v, "must be finite"))
            }
        };
        finite("t0", self.t0)?;
        finite("t_end", self.t_end)?;
        if self.t_end < self.t0 {
            return Err(invalid("t_end", self.t_end, "must not be before t0"));
        }
        for (name, v) in [("q0", &self.q0), ("qd0", &self.qd0)] {
            if let Some(v) = v {
                if v.len() != nq {
                    return Err(invalid(
                        name,
                        format!("{} values (the model has {nq} coordinates)", v.len()),
                        "must have one value per coordinate",
                    ));
                }
                if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                    return Err(invalid(
                        name,
                        format!("{} at coordinate {i}", v[i]),
                        "every initial value must be finite",
                    ));
                }
            }
        }
        match self.step {
            StepControl::Fixed { h } => {
                if !(h > 0.0) || !h.is_finite() {
                    return Err(invalid("h", h, "must be > 0 and finite"));
                }
                let t_far = self.t0.abs().max(self.t_end.abs());
                if h < 64.0 * f64::EPSILON * t_far {
                    return Err(invalid(
                        "h",
                        format!("{} (with t_end = {})", short(h), short(self.t_end)),
                        "the fixed step is below the resolution of time there (64 ε·|t|): t + h would not move; take a larger h or a shorter run",
                    ));
                }
                if let Some(h_min) = self.h_min {
                    if h_min > h {
                        return Err(invalid(
                            "h_min",
                            format!("{} (with the fixed step h = {})", short(h_min), short(h)),
                            "h_min bounds adaptive steps and is above the fixed step: a fixed step is not judged by h_min; drop h_min (None) or take h ≥ h_min",
                        ));
                    }
                }
            }
            StepControl::Adaptive { rtol, atol, h0 } => {
                if !scheme.is_adaptive() {
                    return Err(invalid(
                        "step",
                        scheme.name(),
                        "this scheme has no error estimate: use StepControl::Fixed",
                    ));
                }
                if !(rtol > 0.0) || !rtol.is_finite() {
                    return Err(invalid("rtol", rtol, "must be > 0"));
                }
                if rtol >= 1.0 {
                    return Err(invalid(
                        "rtol",
                        rtol,
                        "must be < 1: a relative tolerance of 100 % accepts any step, and the motion grows without a word (a double pendulum at rtol 2 reached 7e17 rad/s); take 1e-3 for about 3 digits",
                    ));
                }
                if rtol < 10.0 * f64::EPSILON {
                    return Err(invalid(
                        "rtol",
                        rtol,
                        "must be at least 10 ε (2.2e-15): no scheme resolves below rounding",
                    ));
                }
                if atol.is_infinite() {
                    return Err(invalid("atol", atol, "must be finite"));
                }
                if !(atol > 0.0) {
                    return Err(invalid(
                        "atol",
                        atol,
                        "must be > 0: under atol = 0 a component at zero (a start at rest) has no tolerance at all; take the magnitude below which a component need not be resolved (rtol/100 by default)",
                    ));
                }
                if let Some(h0) = h0 {
                    if !(h0 > 0.0) || !h0.is_finite() {
                        return Err(invalid("h0", h0, "must be > 0 and finite"));
                    }
                    let h_min = self.h_min_at(self.t0);
                    if h0 < h_min {
                        return Err(invalid(
                            "h0",
                            format!("{} (with h_min = {})", short(h0), short(h_min)),
                            "the first step is below h_min, so the run would stop at once: take h0 ≥ h_min or a smaller h_min",
                        ));
                    }
                }
            }
        }
        if !(self.h_max > 0.0) {
            return Err(invalid("h_max", self.h_max, "must be > 0"));
        }
        // a step below 64 ε·|t| does not move t
        let t_far = self.t0.abs().max(self.t_end.abs());
        let resolution = 64.0 * f64::EPSILON * t_far;
        match self.step {
            StepControl::Fixed { h } if self.h_max < h => {
                return Err(invalid(
                    "h_max",
                    format!(
                        "{} (with the fixed step h = {})",
                        short(self.h_max),
                        short(h)
                    ),
                    "is below the fixed step, which is taken as given: drop h_max or take h ≤ h_max",
                ));
            }
            StepControl::Adaptive { .. } => {
                for (name, v) in [("h_max", Some(self.h_max)), ("h_min", self.h_min)] {
                    if let Some(v) = v
                        && v < resolution
                    {
                        return Err(invalid(
                            name,
                            format!("{} (with t = {})", short(v), short(t_far)),
                            "is below the resolution of time there (64 ε·|t|): a step that small would not move t",
                        ));
                    }
                }
            }
            _ => {}
        }
        if let Some(h) = self.h_min {
            if !(h > 0.0) || !h.is_finite() {
                return Err(invalid("h_min", h, "must be > 0 and finite"));
            }
            if h > self.h_max && matches!(self.step, StepControl::Adaptive { .. }) {
                return Err(invalid(
                    "h_min",
                    format!("{} (with h_max = {})", short(h), short(self.h_max)),
                    "h_min is above h_max, so no step is allowed: take h_min ≤ h_max",
                ));
            }
            let span = (self.t_end - self.t0).abs();
            if h > span && span > 0.0 && matches!(self.step, StepControl::Adaptive { .. }) {
                return Err(invalid(
                    "h_min",
                    format!("{} (with a run of {} s)", short(h), short(span)),
                    "h_min is above the length of the run, so the first step that is rejected stops it: take h_min well below t_end − t0",
                ));
            }
        }
        if !(0.0..1.0).contains(&self.singularity_tol) {
            return Err(invalid(
                "singularity_tol",
                self.singularity_tol,
                "must be in [0, 1) (0 disables the check)",
            ));
        }
        if !(0.0..1.0).contains(&self.chart_switch) {
            return Err(invalid(
                "chart_switch",
                self.chart_switch,
                "must be in [0, 1): the |cos b| of a rotation joint below which its chart is re-centred (0 never re-centres)",
            ));
        }
        if self.max_steps == 0 {
            return Err(invalid("max_steps", 0, "must be > 0"));
        }
        match &self.output {
            Output::Every { dt } if !(*dt > 0.0) || !dt.is_finite() => {
                return Err(invalid("output.dt", dt, "must be > 0 and finite"));
            }
            Output::Every { dt } if (self.t_end - self.t0) / dt > MAX_OUTPUTS => {
                return Err(invalid(
                    "output.dt",
                    format!(
                        "{} (with t_end − t0 = {})",
                        short(*dt),
                        short(self.t_end - self.t0)
                    ),
                    "gives more than 10⁸ outputs, more than the trajectory can hold: take a larger dt (or, in Rust, Output::Steps or Output::Last)",
                ));
            }
            Output::Every { dt }
                if *dt < 64.0 * f64::EPSILON * self.t0.abs().max(self.t_end.abs()) =>
            {
                return Err(invalid(
                    "output.dt",
                    format!("{} (with t_end = {})", short(*dt), short(self.t_end)),
                    "is below the resolution of time there (64 ε·|t|): outputs that close would repeat the same time; take a larger dt",
                ));
            }
            Output::Times(ts) => {
                // the first offending time by its index, not the whole list
                if let Some(k) = ts
                    .iter()
                    .position(|t| !t.is_finite() || *t < self.t0 || *t > self.t_end)
                {
                    return Err(invalid(
                        "output.times",
                        format!(
                            "{} at index {k} (t0 = {}, t_end = {})",
                            short(ts[k]),
                            short(self.t0),
                            short(self.t_end)
                        ),
                        "must be finite and within [t0, t_end]",
                    ));
                }
                if let Some(k) = ts.windows(2).position(|w| w[1] < w[0]) {
                    return Err(invalid(
                        "output.times",
                        format!(
                            "{} at index {} after {}",
                            short(ts[k + 1]),
                            k + 1,
                            short(ts[k])
                        ),
                        "must be sorted",
                    ));
                }
            }
            _ => {}
        }
        let n = &self.newton;
        if n.max_iterations == 0 || n.max_iterations > 1_000_000 {
            return Err(invalid(
                "newton.max_iterations",
                n.max_iterations,
                "must be from 1 to 10⁶ (a Newton iteration that has not converged in a few dozen will not)",
            ));
        }
        for (name, v) in [
            ("newton.tolerance_factor", n.tolerance_factor),
            ("newton.atol", n.atol),
            ("newton.rtol", n.rtol),
        ] {
            if !(v > 0.0) || !v.is_finite() {
                return Err(invalid(name, v, "must be > 0 and finite"));
            }
        }
        if let Some(keep) = n.keep_below.filter(|k| !(*k > 0.0 && *k < 1.0)) {
            return Err(invalid(
                "newton.keep_below",
                keep,
                "must be in (0, 1): a contraction θ below it keeps Radau's iteration matrices (0.001 by default, 0.1 where they are costly); set newton.reuse = false to re-evaluate them at every step",
            ));
        }
        let c = &self.constraints;
        c.validate()?;
        if let ConstraintMethod::Baumgarte { alpha, beta } = c.method {
            if !(alpha >= 0.0 && beta >= 0.0 && alpha.is_finite() && beta.is_finite()) {
                return Err(invalid(
                    "constraints.method",
                    // as `ConstraintMethod::from_name` and the command line write it
                    format!("baumgarte:{alpha},{beta}"),
                    "α and β must be finite and ≥ 0 (negative values destabilise the constraints)",
                ));
            }
        }
        if self.iteration_matrix == IterationMatrix::Exact && !has_tangents {
            return Err(invalid(
                "iteration_matrix",
                "Exact",
                "the model was generated without tangents: add `option tangents;` to its multibody! block, or use Auto, MassOnly or FiniteDifferences",
            ));
        }
        validate_scheme(scheme)
    }
}

/// The most outputs `Output::Every` may ask for: 10⁸ (the trajectory stores q, q̇ and q̈ of
/// each, 2.4 GB for a single coordinate).
const MAX_OUTPUTS: f64 = 1e8;

/// Parameters of a scheme within their ranges of stability.
pub fn validate_scheme(scheme: &Scheme) -> Result<(), Failure> {
    match *scheme {
        Scheme::Newmark(p) => {
            if !p.beta.is_finite() || !p.gamma.is_finite() {
                return Err(invalid(
                    "newmark.beta/gamma",
                    format!("{}/{}", p.beta, p.gamma),
                    "must be finite",
                ));
            }
            if p.gamma < 0.5 {
                return Err(invalid(
                    "newmark.gamma",
                    p.gamma,
                    "γ < ½ amplifies oscillations (negative numerical damping): use γ ≥ ½",
                ));
            }
            let b_min = 0.25 * (p.gamma + 0.5) * (p.gamma + 0.5);
            if p.beta < b_min - 1e-15 {
                return Err(invalid(
                    "newmark.beta",
                    p.beta,
                    "β < ¼(γ + ½)² is only conditionally stable: use β ≥ ¼(γ + ½)² (β = ¼ for γ = ½)",
                ));
            }
        }
        Scheme::Hht(p) if !(-1.0 / 3.0 - 1e-15..=0.0).contains(&p.alpha) => {
            return Err(invalid("hht.alpha", p.alpha, "must be in [−1/3, 0]"));
        }
        Scheme::GenAlpha(p) => {
            if !p.rho_inf.is_nan() && !(0.0..=1.0).contains(&p.rho_inf) {
                return Err(invalid("gen_alpha.rho_inf", p.rho_inf, "must be in [0, 1]"));
            }
            let ok = p.alpha_m <= p.alpha_f
                && p.alpha_f <= 0.5
                && (p.gamma - (0.5 - p.alpha_m + p.alpha_f)).abs() < 1e-12
                && p.beta >= 0.25 * (0.5 + p.gamma) * (0.5 + p.gamma) - 1e-12;
            if !ok
                || [p.alpha_m, p.alpha_f, p.beta, p.gamma]
                    .iter()
                    .any(|x| !x.is_finite())
            {
                return Err(invalid(
                    "gen_alpha",
                    format!(
                        "α_m {} α_f {} β {} γ {}",
                        p.alpha_m, p.alpha_f, p.beta, p.gamma
                    ),
                    "not second-order and unconditionally stable: build it with GenAlphaParams::from_rho_inf(ρ∞)",
                ));
            }
        }
        Scheme::Bdf(p) if !(1..=5).contains(&p.max_order) => {
            return Err(invalid(
                "bdf.max_order",
                p.max_order,
                "must be 1 to 5 (BDF 6+ is unstable)",
            ));
        }
        _ => {}
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gen_alpha_from_rho_inf() {
        let p = GenAlphaParams::from_rho_inf(1.0);
        assert!((p.alpha_m - 0.5).abs() < 1e-15 && (p.alpha_f - 0.5).abs() < 1e-15);
        assert!((p.gamma - 0.5).abs() < 1e-15 && (p.beta - 0.25).abs() < 1e-15);
        assert!(validate_scheme(&Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.0))).is_ok());
        assert!(validate_scheme(&Scheme::GenAlpha(GenAlphaParams::from_rho_inf(1.2))).is_err());
    }

    #[test]
    fn bad_options_are_named() {
        let e = Options {
            t_end: -1.0,
            ..Options::default()
        }
        .validate(&Scheme::Rk4, 2, false)
        .unwrap_err();
        assert!(matches!(e, Failure::InvalidOption { name: "t_end", .. }));
        let e = Options::adaptive(1.0, 1e-17)
            .validate(&Scheme::Dopri5, 2, false)
            .unwrap_err();
        assert!(matches!(e, Failure::InvalidOption { name: "rtol", .. }));
        // tiny and huge values read as written, not as 300 digits
        let e = Options::adaptive(1.0, 1e-300)
            .validate(&Scheme::Dopri5, 2, false)
            .unwrap_err();
        assert!(
            matches!(&e, Failure::InvalidOption { value, .. } if value == "1e-300"),
            "{e}"
        );
        let e = Options::adaptive(1.0, 1e-6)
            .validate(&Scheme::Rk4, 2, false)
            .unwrap_err();
        assert!(matches!(e, Failure::InvalidOption { name: "step", .. }));
        let e = Options::fixed(1.0, 0.0)
            .validate(&Scheme::Rk4, 2, false)
            .unwrap_err();
        assert!(matches!(e, Failure::InvalidOption { name: "h", .. }));
        let bad = Scheme::Newmark(NewmarkParams {
            beta: 0.1,
            gamma: 0.5,
        });
        assert!(matches!(
            Options::fixed(1.0, 0.1).validate(&bad, 2, false),
            Err(Failure::InvalidOption {
                name: "newmark.beta",
                ..
            })
        ));
        let bad = Scheme::Hht(HhtParams { alpha: 0.1 });
        assert!(matches!(
            Options::fixed(1.0, 0.1).validate(&bad, 2, false),
            Err(Failure::InvalidOption {
                name: "hht.alpha",
                ..
            })
        ));
        let o = Options {
            iteration_matrix: IterationMatrix::Exact,
            ..Options::fixed(1.0, 0.1)
        };
        assert!(matches!(
            o.validate(&Scheme::ImplicitMidpoint, 2, false),
            Err(Failure::InvalidOption {
                name: "iteration_matrix",
                ..
            })
        ));
    }
}
