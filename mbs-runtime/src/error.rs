//! Typed errors of models and parameters.

use thiserror::Error;

/// A parameter value that no physical system has.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ParamError {
    #[error("parameter `{name}` is {value}: parameters must be finite")]
    NonFinite { name: &'static str, value: f64 },
    #[error("unknown parameter `{name}`; the parameters are: {known}")]
    Unknown { name: String, known: String },
    #[error(
        "body `{body}` has mass {value}: a body's mass must be positive (a massless part is a `frame`)"
    )]
    NonPositiveMass { body: &'static str, value: f64 },
    #[error("inertia of body `{body}` is not physical: {reason}")]
    InvalidInertia { body: &'static str, reason: String },
    #[error("spring number {index} has stiffness {value}: a stiffness must not be negative")]
    NegativeStiffness { index: usize, value: f64 },
    #[error("{element} (in declaration order) has {name} = {value}: it {rule}")]
    InvalidCoefficient {
        element: &'static str,
        name: &'static str,
        value: f64,
        rule: &'static str,
    },
}

/// A model asked for something it does not have.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ModelError {
    #[error(
        "model `{model}` was generated without tangents: add `option tangents;` to its multibody! block, or use an iteration matrix that needs none"
    )]
    TangentsNotGenerated { model: &'static str },
    #[error(
        "model `{model}` has no sensitive parameters: mark those you want derivatives for, `param k = 1e4 sensitive;`"
    )]
    NoSensitiveParameters { model: &'static str },
}

/// `x` with at most 10 significant digits and no trailing zeros (`0.2394270743`, `2.5`,
/// `1.5e-7`): times and steps in messages read like the numbers a user types, not like the
/// 17 digits of a round trip.
pub fn short(x: f64) -> String {
    fn trim(s: &str) -> &str {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.')
        } else {
            s
        }
    }
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if (1e-4..1e7).contains(&a) {
        let decimals = (9 - a.log10().floor() as i32).max(0) as usize;
        trim(&format!("{x:.decimals$}")).to_string()
    } else {
        let s = format!("{x:.9e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        format!("{}e{exponent}", trim(mantissa))
    }
}

/// Checks an inertia tensor (xx, yy, zz, xy, xz, yz) about G; generated `validate()` calls it.
pub fn check_inertia(body: &'static str, t: [f64; 6]) -> Result<(), ParamError> {
    match crate::inertia::inertia_problem(t) {
        None => Ok(()),
        Some(reason) => Err(ParamError::InvalidInertia { body, reason }),
    }
}

/// What [`Failure::UnstableStep`]'s message says before its advice (a step to take): that
/// h·ρ leaves the scheme's stability region, with h·ρ in three decimals, or three digits of a
/// power of ten past 10⁶ (a step that blew the state up gives h·ρ of 1e39, not 40 digits),
/// and, when ρ was read at the end of the step, that the step lurched.
pub fn unstable_text(scheme: &str, rho: f64, h_rho: f64, limit: f64, at_end: bool) -> String {
    let h_rho = if h_rho.abs() < 1e6 {
        format!("{h_rho:.3}")
    } else {
        format!("{h_rho:.3e}")
    };
    let (lurched, there) = if at_end {
        (LURCHED, " there")
    } else {
        ("", "")
    };
    format!(
        "{lurched}h·ρ = {h_rho} leaves the stability region of {scheme} (limit {limit:.3}; ρ ≈ {rho:.4e} 1/s is the fastest mode{there})"
    )
}

/// The growth past which a component whose tolerance rtol set has run away
/// ([`HeldBy::ran_away`]): a million times the largest entry of its kind at the start.
pub const RAN_AWAY: f64 = 1e6;

/// How [`Failure::UnstableStep`] starts when ρ was estimated at the end of the step.
const LURCHED: &str = "the step changed the state by more than its own size: at its end ";

/// The component that weighed most in the last error test before the step fell below h_min
/// (a test that rejected the step, or accepted it and chose a next step below h_min), named
/// in the failure: a step held by one coordinate of a stiff or singular motion, or by a
/// tolerance tighter than the arithmetic resolves.
#[derive(Debug, Clone, PartialEq)]
pub struct HeldBy {
    /// `q[7] (name)`, `the velocity of q[7] (name)` or `λ[2]`
    pub component: String,
    /// its magnitude, max(|y| before, |y| after the step)
    pub value: f64,
    /// its error estimate
    pub error: f64,
    /// its weight in the test: the scheme's local tolerance atol' + rtol'·|y|, or the rounding
    /// floor
    pub tolerance: f64,
    /// what set the weight: `"atol"`, `"rtol"` or `"rounding"` (100ε times the largest entry
    /// of its kind)
    pub set_by: &'static str,
    /// the largest entry of its kind (positions or velocities) in the state the run started
    /// from; none for a multiplier
    pub start: Option<f64>,
}

/// A run that ran out of steps while its scheme's local error test held its floor rather
/// than the tolerance its map of rtol asked ([`Stats::tolerance_floor`](crate::Stats)): every
/// rtol below `from` holds the same floor and takes as many steps, so that loosening rtol
/// saves steps only above it (the four-bar under Radau3 at index 3 at rtol 1e-10, its floor
/// 10⁵ε held from rtol ≈ 3.8e-8 on, ran out of 20,000 steps, and was told to loosen rtol).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FlooredTolerance {
    /// the local tolerance the error test held
    pub floor: f64,
    /// the loosest rtol whose local tolerance is that floor (within a part in 10⁶)
    pub from: f64,
}

impl FlooredTolerance {
    /// "; its local error test held its floor …", with the option named `rtol` (`--rtol` on
    /// a command line); empty without a floor.
    pub fn clause(floored: &Option<Box<FlooredTolerance>>, rtol: &str) -> String {
        match floored.as_deref() {
            None => String::new(),
            Some(f) => format!(
                "; its local error test held its floor of {:.1e}, as it does at every {rtol} below {:.2e}: a looser {rtol} takes fewer steps only above that",
                f.floor, f.from
            ),
        }
    }
}

/// Closed loops near a change point or dead centre when a step failed at h_min: the pivot
/// ratio the loops' watch last judged ([`Options::singularity_tol`](crate::Options)), within a
/// hundred times the threshold at which it stops the run with [`Failure::SingularLoop`]. Near
/// there B's rounding errors are amplified (by σ₀/σ in the coordinates that solve Φ and Φ̇,
/// (σ₀/σ)² in λ) and a step may fail for that before the watch speaks: the parallelogram
/// four-bar under Radau3 at index 2 at rtol 1e-8 stopped in its error test, held by the
/// folding angle's velocity, 0.010 rad before its change point, at a ratio of 1.2e-4.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct NearChangePoint {
    /// the pivot of B Bᵀ or S = B M⁻¹ Bᵀ that fell most, against its start value
    pub ratio: f64,
    /// `Options::singularity_tol`
    pub tolerance: f64,
}

impl NearChangePoint {
    /// How far within the threshold a ratio counts as near: a hundred times it.
    pub const NEAR: f64 = 100.0;

    /// The clause a failure's message ends with, empty when `near` is none.
    pub fn clause(near: &Option<NearChangePoint>) -> String {
        near.map(|n| {
            format!(
                "; the closed loops are near a change point or dead centre (a pivot of their \
                 constraints' matrix fell to {:.1e} of its start value; singularity_tol = {:.0e} \
                 stops the run there with SingularLoop), where rounding errors grow as the \
                 pivot falls and a step may fail for that: loosen atol or end the run before it",
                n.ratio, n.tolerance
            )
        })
        .unwrap_or_default()
    }
}

/// The coordinate (its position or velocity) or multiplier whose term weighed most in the
/// error tests of the most accepted steps of a run: what kept the steps small when a run runs
/// out of steps.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HeldMost {
    /// `q[7] (name) (its position or velocity)` or `λ[2]`
    pub component: String,
    /// the accepted steps it held, and the accepted steps with an error test
    pub steps: usize,
    pub of: usize,
}

impl HeldMost {
    /// "; the error test was held by … in 87 % of the 1204 accepted steps" (empty without
    /// one).
    pub fn clause(held_most: &Option<HeldMost>) -> String {
        held_most
            .as_ref()
            .map_or(String::new(), |h| format!("; {h}"))
    }
}

impl std::fmt::Display for HeldMost {
    /// "the error test was held by … in 87 % of the 1204 accepted steps".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the error test was held by {} in {:.0} % of the {} accepted steps",
            self.component,
            100.0 * self.steps as f64 / self.of.max(1) as f64,
            self.of
        )
    }
}

/// Why a run ran out of steps, as far as its scheme and step control tell, and so what to
/// change: the advice of [`Failure::TooMuchWork`] (a scheme that detected stiffness stops with
/// [`Failure::LikelyStiff`] instead).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutOfSteps {
    /// a fixed step, whose run needs this many steps ((t_end − t0)/h rounded up)
    Fixed(u64),
    /// an adaptive scheme of order 2 (the Newmark family, the implicit midpoint rule), whose
    /// steps shrink as the square root of the tolerance
    OrderTwo(&'static str),
    /// RKC: of order 2, and stable along the negative real axis (damped modes) only
    Rkc,
    /// an implicit scheme of high order (Radau IIA, BDF), made for stiff problems
    Implicit(&'static str),
    /// an explicit scheme of high order whose stiffness detection did not fire (DOPRI5): its
    /// steps may still be held by stiff modes within its stability region
    Explicit(&'static str),
}

impl OutOfSteps {
    /// The cause for the scheme named `scheme` ([`Scheme::name`](crate::Scheme::name)), with
    /// `needed` steps at a fixed step.
    pub fn of(scheme: &'static str, needed: Option<u64>) -> OutOfSteps {
        match (needed, scheme) {
            (Some(n), _) => OutOfSteps::Fixed(n),
            (None, "rkc") => OutOfSteps::Rkc,
            (None, "radau3" | "radau5" | "bdf") => OutOfSteps::Implicit(scheme),
            (None, "dopri5" | "euler" | "rk4") => OutOfSteps::Explicit(scheme),
            (None, _) => OutOfSteps::OrderTwo(scheme),
        }
    }

    /// The advice, with the options named as the caller spells them: `max_steps`, `rtol`,
    /// `larger_step` (what a larger fixed step is called) and `scheme` (the prefix of a
    /// scheme's name: `--scheme ` on a command line).
    pub fn advice(&self, max_steps: &str, rtol: &str, larger_step: &str, scheme: &str) -> String {
        match self {
            OutOfSteps::Fixed(n) => format!(
                "at its fixed step the run needs {n} steps: raise {max_steps} to {n} or more, or take {larger_step}"
            ),
            OutOfSteps::OrderTwo(s) => format!(
                "{s} is of order 2, whose steps shrink as the square root of the tolerance: loosen {rtol}, raise {max_steps}, or use a scheme of higher order ({scheme}radau5 or {scheme}bdf)"
            ),
            OutOfSteps::Rkc => format!(
                "rkc is of order 2 and stable along the negative real axis only (damped modes): loosen {rtol} or raise {max_steps}; for accuracy on a problem that is not stiff use {scheme}dopri5, for stiff oscillation {scheme}radau5 or {scheme}bdf"
            ),
            OutOfSteps::Implicit(s) => format!(
                "raise {max_steps} or loosen {rtol} ({s} is already a scheme for stiff problems: its steps were what its error test or its Newton iteration asked)"
            ),
            OutOfSteps::Explicit(s) => format!(
                "raise {max_steps} or loosen {rtol}; {s}'s stiffness detection did not find its steps held by its stability region, but a problem with fast decaying modes (a stiff spring or damper, large Baumgarte gains) is better run by {scheme}radau5 or {scheme}bdf"
            ),
        }
    }
}

impl HeldBy {
    /// What follows "the step fell below h_min": that the solution may be singular or too
    /// stiff, and the component the error test was held by; where the tolerance was atol's
    /// or the rounding floor, the fix instead (raise atol).
    ///
    /// With a floor the user `given`, the step may only have needed to be smaller than it:
    /// the clause says to lower it before it speaks of stiffness.
    pub fn clause(held_by: &Option<Box<HeldBy>>, given: bool, jump: Option<f64>) -> String {
        let ran_away = held_by.as_ref().is_some_and(|b| b.ran_away());
        if let (Some(order), false) = (jump, ran_away) {
            return format!(": {}", HeldBy::not_smooth(held_by, order, "atol"));
        }
        let stiff = if given {
            " (lower h_min if the motion may need smaller steps than that; otherwise the solution may be singular or too stiff for the scheme)"
        } else {
            " (the solution may be singular or too stiff for the scheme)"
        };
        match held_by {
            None => stiff.into(),
            Some(b) => match b.fix("atol", "rtol") {
                Some(fix) => format!(": {fix}"),
                None => format!("{stiff}; {}", b.held()),
            },
        }
    }

    /// What to change when the step fell below h_min for a reason other than the motion's
    /// stiffness, with the options named `atol` and `rtol` (`--atol`, `--rtol` on a command
    /// line): raise atol when its tolerance or the rounding floor held the step
    /// ([`HeldBy::advice`]), tighten rtol when the motion ran away ([`HeldBy::runaway`]);
    /// `None` otherwise.
    pub fn fix(&self, atol: &str, rtol: &str) -> Option<String> {
        if self.tolerance_is_the_fix() {
            Some(self.advice(atol))
        } else if self.ran_away() {
            Some(self.runaway(rtol))
        } else {
            None
        }
    }

    /// "the motion ran away: … tighten rtol" (the option's name: `--rtol` on a command line),
    /// for a component that [ran away](HeldBy::ran_away).
    pub fn runaway(&self, rtol: &str) -> String {
        format!(
            "the motion ran away: {} grew to {:.1e} where the largest entry of its kind was {} at the start; a relative tolerance lets each step's error grow with the motion, and a motion that gains energy from those errors runs away (DOPRI5 on the double pendulum released at rest: at rtol 0.2 within 1.4 s, at 0.02 within 34 s); tighten {rtol} ({})",
            self.component,
            self.value,
            match self.start {
                Some(0.0) => "0".to_string(),
                Some(v) => format!("{v:.1e}"),
                None => "unknown".to_string(),
            },
            self.held()
        )
    }

    /// What a step that fell below h_min while its error fell with it only at `order` (below
    /// 1.5) says: the forces are not smooth within the step ([`HeldBy::jump`]), with the
    /// component the test was held by; or, where that component's tolerance was the rounding
    /// floor, that its error is rounding, which no shorter step reduces, and to raise `atol`
    /// (fastlink under Radau5 at index 3 with a local tolerance of 10⁴ε, below its floor, was
    /// said to have forces that jump at t = 1.6e-4 s, its crank's velocity held at 4e-14, 100ε
    /// of the largest).
    pub fn not_smooth(held_by: &Option<Box<HeldBy>>, order: f64, atol: &str) -> String {
        match held_by.as_deref() {
            Some(b) if b.set_by == "rounding" => format!(
                "the error fell with the step only at order {order:.1} as it shrank, as rounding errors do: {}",
                b.advice(atol)
            ),
            Some(b) => format!("{}; {}", HeldBy::jump(order, atol), b.held()),
            None => HeldBy::jump(order, atol),
        }
    }

    /// "the error fell with the step at order …": forces that are not smooth within the step,
    /// by the `order` at which the error fell with h over the last rejections (below 1.5,
    /// where a smooth motion gives the scheme's order + 1), with the tolerance named `atol`.
    pub fn jump(order: f64, atol: &str) -> String {
        format!(
            "the error fell with the step only at order {order:.1} as it shrank, where a smooth motion gives the scheme's order + 1: the forces are likely not smooth here (a jump, as a contact's damping force at touchdown or an input that steps, or a law that switches at a threshold of a coordinate or a rate), and a step across that errs by an amount that shrinking it hardly reduces (about h·Δa for a jump Δa); make the force continuous there (a regularisation over a small width), stop and restart the run at the event, or raise {atol} to what such a step can meet"
        )
    }

    /// Whether rtol set the tolerance of a position or velocity that grew past [`RAN_AWAY`]
    /// times the largest entry of its kind at the start (or [`RAN_AWAY`] in SI units, from
    /// rest): the steps fell below h_min because the motion ran away, not because it is stiff.
    pub fn ran_away(&self) -> bool {
        self.set_by == "rtol"
            && self
                .start
                .is_some_and(|start| self.value > RAN_AWAY * start.max(1.0))
    }

    /// Whether the tolerance, not the motion, held the step: it was atol's or the rounding
    /// floor's.
    pub fn tolerance_is_the_fix(&self) -> bool {
        matches!(self.set_by, "atol" | "rounding")
    }

    /// "the error test was held by … set by …", and for a tolerance of atol or of the
    /// rounding floor the fix, raising `atol` (the option's name: `--atol` on a command
    /// line).
    pub fn advice(&self, atol: &str) -> String {
        match self.set_by {
            "atol" => format!(
                "{}: if a component this small need not be resolved so finely, raise {atol}",
                self.held()
            ),
            "rounding" => format!(
                "{} (100ε times the largest entry of its kind), above what atol and rtol asked: raise {atol} to at least that",
                self.held()
            ),
            _ => self.held(),
        }
    }

    /// "the error test was held by C = v, its error e against a tolerance of w set by …".
    pub fn held(&self) -> String {
        format!(
            "the error test was held by {} = {:.3e}, its error {:.2e} against a tolerance of {:.2e} set by {}",
            self.component, self.value, self.error, self.tolerance, self.set_by
        )
    }
}

/// The matrix a closed loop's watch factorises ([`Failure::SingularLoop`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum LoopMatrix {
    /// S = B M⁻¹ Bᵀ, of every index-1 solve
    Schur,
    /// B Bᵀ, after every step of the index-3 and stabilized index-2 forms
    Gram,
}

impl std::fmt::Display for LoopMatrix {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LoopMatrix::Schur => "S = B M⁻¹ Bᵀ",
            LoopMatrix::Gram => "B Bᵀ",
        })
    }
}

/// Why a simulation stopped early. Each variant carries what is needed to act on it; the
/// time, step, work done and the trajectory so far travel with it in
/// [`SimError`](crate::SimError).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Failure {
    #[error("option `{name}` = {value} is invalid: {reason}")]
    InvalidOption {
        name: &'static str,
        value: String,
        reason: &'static str,
    },
    #[error("invalid parameters: {0}")]
    InvalidParameters(ParamError),
    #[error(
        "the step fell below h_min = {h_min:e}{}{}{}",
        if *given { ", the floor given in Options::h_min" } else { "" },
        HeldBy::clause(held_by, *given, *jump),
        NearChangePoint::clause(near_change_point)
    )]
    StepTooSmall {
        h_min: f64,
        /// the component that weighed most in the last error test (none when the scheme has
        /// no error test, or rejected the step for another cause)
        held_by: Option<Box<HeldBy>>,
        /// whether h_min is the user's ([`Options::h_min`](crate::Options::h_min)) rather than
        /// the default 1e-12·|t|: then the step may simply have needed to be smaller
        given: bool,
        /// the order at which the error fell with the step over the last rejections, when
        /// below 1.5: forces that are not smooth within the step, a jump (about 1) or a law
        /// that switches with the state (about 0) ([`HeldBy::jump`])
        jump: Option<f64>,
        /// closed loops near a change point when the step failed
        near_change_point: Option<NearChangePoint>,
    },
    #[error(
        "more than {max_steps} steps: {}{}{}",
        cause.advice("Options::max_steps", "rtol", "a larger fixed step", ""),
        FlooredTolerance::clause(floored, "rtol"),
        HeldMost::clause(held_most)
    )]
    TooMuchWork {
        max_steps: usize,
        /// the component whose error test held the most accepted steps (none without an
        /// error test)
        held_most: Option<HeldMost>,
        /// what the kind of step and the scheme say of the cause, and so what to change
        cause: OutOfSteps,
        /// the local tolerance at the scheme's floor, where rtol asked for less
        floored: Option<Box<FlooredTolerance>>,
    },
    #[error(
        "Newton did not converge in {iterations} iterations (last correction {correction:.2e}{}) {}{}",
        largest.as_ref().map(|c| format!(", largest in {c}")).unwrap_or_default(),
        if *fixed {
            "at the fixed step, which is not reduced: take a smaller step (StepControl::Fixed)"
        } else {
            "at the smallest step allowed (h_min)"
        },
        NearChangePoint::clause(near_change_point)
    )]
    NewtonDiverged {
        iterations: usize,
        correction: f64,
        /// the component of the last correction with the largest weighted term
        largest: Option<String>,
        /// whether the step was the user's fixed step (else the adaptive step at h_min)
        fixed: bool,
        /// closed loops near a change point when the step failed
        near_change_point: Option<NearChangePoint>,
    },
    #[error(
        "{matrix} is singular (rcond ≈ {rcond:.1e}){}{cause}",
        if coordinates.is_empty() { String::new() } else { format!(" near coordinates {}", coordinates.join(", ")) }
    )]
    SingularMatrix {
        matrix: &'static str,
        rcond: f64,
        coordinates: Vec<String>,
        /// at the start of a run, the parameters that make M regular when set back to their
        /// defaults alone ("; with `l` at its default 1 rather than 0 …"); empty otherwise
        cause: String,
    },
    #[error(
        "the coordinates reach a singular configuration at {coordinate} = {value:.6} (Euler angles at gimbal lock, joint axes lining up, a coordinate that stops moving mass): the mass matrix is nearly singular along {} (a pivot of its factorisation fell to {ratio:.1e} of its start value, below singularity_tol = {tolerance:.0e}); describe this motion with other coordinates",
        dependent.join(", ")
    )]
    SingularConfiguration {
        /// the coordinate the singularity depends on: the largest |∂ log det M/∂q_j|
        coordinate: String,
        /// its value
        value: f64,
        /// the coordinates of the near-null vector of M (scaled by its start diagonal): the
        /// ones that move the bodies alike, or no longer move them
        dependent: Vec<String>,
        /// the pivot of M's factorisation (dense Cholesky, or the generated forward dynamics)
        /// that fell most, over its start value
        ratio: f64,
        /// `Options::singularity_tol`
        tolerance: f64,
    },
    #[error(
        "the closed loops reach a singular configuration at {coordinate} = {value:.6} (a change point or dead centre): B = ∂Φ/∂q nearly loses rank in the constraints {} (a pivot of {matrix} fell to {ratio:.1e} of its start value, below singularity_tol = {tolerance:.0e}), and the motion through it is not unique (the mechanism may switch branch): add what decides it (a constraint, a stop, a driving input) or end the run before it",
        constraints.join(", ")
    )]
    SingularLoop {
        /// the coordinate the singularity depends on: the largest |∂ log det (B Bᵀ)/∂q_j|
        coordinate: String,
        /// its value
        value: f64,
        /// the constraints of B's smallest singular value (its left singular vector)
        constraints: Vec<String>,
        /// the matrix whose factorisation was watched
        matrix: LoopMatrix,
        /// the pivot of its Cholesky factor that fell most, over its start value
        ratio: f64,
        /// `Options::singularity_tol`
        tolerance: f64,
    },
    #[error("{}", non_finite_text(quantity, coordinate, cause))]
    NonFinite {
        quantity: &'static str,
        coordinate: String,
        /// at the start, the parameters that make it finite when set back to their defaults
        /// alone ("; with `g` at its default 9.81 rather than 1e300 the start is finite"),
        /// or that they are all at their defaults; empty otherwise
        cause: String,
    },
    #[error(
        "{}: take h < {h_stable:.4e} s or an implicit scheme",
        unstable_text(scheme, *rho, *h_rho, *limit, *at_end)
    )]
    UnstableStep {
        scheme: &'static str,
        rho: f64,
        h_rho: f64,
        limit: f64,
        h_stable: f64,
        /// ρ was estimated at the end of a step that changed the state by more than its own
        /// size (the check before the step had found it stable): h_stable is then at least a
        /// hundredth of the step, since a state the step blew up says little of the model
        at_end: bool,
    },
    #[error(
        "the constraints are redundant or degenerate: B = ∂Φ/∂q has rank {rank} for {nc} constraints (smallest singular value {sigma_min:.2e}); involved: {}; remove the redundant equations (e.g. the out-of-plane ones of a planar loop) or start away from the singular configuration",
        constraints.join(", ")
    )]
    RankDeficientConstraints {
        rank: usize,
        nc: usize,
        sigma_min: f64,
        constraints: Vec<String>,
    },
    #[error(
        "no consistent start: {reason} (largest |Φ| = {residual:.2e}, at constraint `{constraint}`, after {iterations} iterations)"
    )]
    InconsistentStart {
        reason: String,
        constraint: String,
        residual: f64,
        iterations: usize,
    },
    #[error(
        "constraint `{constraint}` drifted to |Φ| = {value:.2e}, beyond drift_tol = {tolerance:.1e}: {}",
        if *.closed_by_scheme { "the scheme closes it at index 3 or 2 by Newton, to constraints.tolerance on its predicted Φ, and the new state landed beyond drift_tol: keep drift_tol well above constraints.tolerance, or use Projection" } else { "use Projection, Index3 or Partitioning, or stronger Baumgarte terms" }
    )]
    ConstraintDrift {
        constraint: String,
        value: f64,
        tolerance: f64,
        /// whether the scheme closes the constraints itself (index 3 or 2), rather than
        /// Baumgarte's terms holding them
        closed_by_scheme: bool,
    },
    #[error(
        "Newton could not close constraint `{constraint}` by moving {what} (|Φ| = {residual:.2e} after {iterations} iterations): the step left the constraints farther than Newton reaches from there; at a fixed step take a smaller one, or adaptive steps, which retry it smaller (with adaptive steps it failed at h_min: near a singular configuration of the loop)"
    )]
    ClosureFailed {
        what: &'static str,
        constraint: String,
        residual: f64,
        iterations: usize,
    },
    #[error("user effort failed at t = {t}: {message}")]
    UserEffort { t: f64, message: String },
    /// A user effort rejected a state ([`crate::Effort::reject`]) and smaller steps did not
    /// avoid it: at a fixed step, or with the step at its floor.
    #[error(
        "user effort rejected the state at t = {t} and smaller steps did not avoid it: {message}"
    )]
    EffortRejected { t: f64, message: String },
    #[error("{scheme} cannot integrate constraints by {method}: {supported}")]
    ConstraintsUnsupported {
        scheme: &'static str,
        method: &'static str,
        supported: &'static str,
    },
    #[error(
        "more than {max_steps} steps on a stiff problem: from t = {} the step of {scheme} was held by its stability region (h·|λ| > 3.25 for 15 accepted steps in a row), not by accuracy; use radau5 or bdf{}",
        short(*t),
        HeldMost::clause(held_most)
    )]
    LikelyStiff {
        scheme: &'static str,
        /// the end of the first run of steps found stiff
        t: f64,
        max_steps: usize,
        /// the component whose error test held the most accepted steps
        held_most: Option<HeldMost>,
    },
    #[error(
        "global error control: {} after {runs} run{}, the most accurate at local rtol {rtol:.1e}{}{}{}; {}",
        estimated(*estimate),
        if *runs == 1 { "" } else { "s" },
        floor.map(GlobalFloor::said).unwrap_or_default(),
        limit.map(GlobalLimit::said).unwrap_or_default(),
        cause.as_ref().map(|c| format!(" (the next run failed: {c})")).unwrap_or_default(),
        global_advice(scheme, floor, limit)
    )]
    GlobalToleranceNotMet {
        /// the scheme ([`Scheme::name`](crate::Scheme::name))
        scheme: &'static str,
        /// the last estimate, in the user's tolerance (1 = met): of the run before the one
        /// kept, whose own error no tighter run checked (it read as the kept run's, which
        /// at a tighter rtol is likely smaller)
        estimate: f64,
        /// the local rtol of the most accurate complete run (the trajectory kept)
        rtol: f64,
        runs: usize,
        /// the runs reached the scheme's floor: no tighter run could check the last
        floor: Option<GlobalFloor>,
        /// a limit of [`GlobalControl`](crate::GlobalControl) ended the runs
        limit: Option<GlobalLimit>,
        /// why the next, tighter run stopped, when it did (`None`: the scheme's floor or a
        /// limit of [`GlobalControl`](crate::GlobalControl) ended the runs)
        cause: Option<Box<Failure>>,
    },
}

/// Why global error control checked no tighter run ([`Failure::GlobalToleranceNotMet`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum GlobalFloor {
    /// the last, tighter run took at most 5 % more steps than the run before: rtol does not
    /// set the scheme's step (its local tolerance is at a floor), and the runs' difference
    /// says nothing of the error
    NoMoreSteps,
    /// the scheme's local error test holds its floor at every local rtol below `from`
    /// ([`Stats::floor_from`](crate::Stats)), where a tighter rtol takes no more steps, and
    /// the last run was too close to it to be checked by a tighter one (the control keeps
    /// its candidates at twice `from` or above, checked by runs at `from` or above)
    Held { from: f64 },
}

impl GlobalFloor {
    fn said(self) -> String {
        match self {
            GlobalFloor::NoMoreSteps => " (the last run took no more steps at a tenth of the tolerance: rtol does not set this scheme's step here, and the runs' difference says nothing of the error)".to_string(),
            GlobalFloor::Held { from } => format!(" (this scheme's local error test holds its floor at every local rtol below {from:.1e}, where a tighter rtol takes no more steps: no run tighter than the last could check it)"),
        }
    }
}

/// Which limit of [`GlobalControl`](crate::GlobalControl) ended the runs of a
/// [`Failure::GlobalToleranceNotMet`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum GlobalLimit {
    /// `max_runs` runs were made
    Runs { max_runs: usize },
    /// the next run would have needed the local rtol `needed`, below `min_rtol`
    MinRtol { needed: f64, min_rtol: f64 },
}

impl GlobalLimit {
    fn said(self) -> String {
        match self {
            GlobalLimit::Runs { max_runs } => {
                format!(" (the most runs allowed, {max_runs}: `GlobalControl::max_runs`)")
            }
            GlobalLimit::MinRtol { needed, min_rtol } => format!(
                " (the next would have needed local rtol {needed:.1e}, below the smallest allowed, {min_rtol:.0e}, `GlobalControl::min_rtol`, near rounding: the motion amplifies each step's error more than this tolerance leaves room for)"
            ),
        }
    }
}

/// The schemes of the highest order (5), whose local error test holds no floor in their
/// default constraint method (Radau5 at index 3 has one, which the floor's advice covers).
const HIGHEST_ORDER: [&str; 2] = ["dopri5", "radau5"];

/// What a [`Failure::GlobalToleranceNotMet`] advises, for `scheme`.
fn global_advice(scheme: &str, floor: &Option<GlobalFloor>, limit: &Option<GlobalLimit>) -> String {
    let highest = HIGHEST_ORDER.contains(&scheme);
    let runs = if matches!(limit, Some(GlobalLimit::Runs { .. })) {
        "raise `GlobalControl::max_runs`, "
    } else {
        ""
    };
    if floor.is_some() {
        "loosen rtol, or use a scheme whose local error test holds no floor there (dopri5, or radau5 with projection, its default)".to_string()
    } else if highest {
        format!("{runs}loosen rtol, or try another constraint method")
    } else {
        format!(
            "{runs}loosen rtol, or use a scheme of higher order whose local error test holds no floor (dopri5, or radau5 with projection, its default) or another constraint method"
        )
    }
}

/// The estimate of a [`Failure::GlobalToleranceNotMet`], in words.
fn estimated(estimate: f64) -> String {
    if estimate.is_finite() {
        format!(
            "the last error estimated, of the run before the most accurate (which no tighter run checked), was {estimate:.3} of the tolerance"
        )
    } else {
        "the error of the trajectory could not be estimated".to_string()
    }
}

impl Failure {
    /// `Ok` when every entry of `v` is finite, else the [`Failure::NonFinite`] of `quantity`
    /// at the first entry i that is not, named by `name(i)`.
    pub(crate) fn non_finite(
        quantity: &'static str,
        v: &[f64],
        name: impl FnOnce(usize) -> String,
    ) -> Result<(), Failure> {
        match v.iter().position(|x| !x.is_finite()) {
            None => Ok(()),
            Some(i) => Err(Failure::NonFinite {
                quantity,
                coordinate: name(i),
                cause: String::new(),
            }),
        }
    }
}

/// [`Failure::NonFinite`]'s message: "of coordinate …" only where one is named (a whole
/// matrix has none).
fn non_finite_text(quantity: &str, coordinate: &str, cause: &str) -> String {
    if coordinate.is_empty() {
        format!("{quantity} is not finite{cause}")
    } else {
        format!("{quantity} of coordinate {coordinate} is not finite{cause}")
    }
}

#[cfg(test)]
mod tests {
    use super::{Failure, HeldBy, short};

    /// A step that fell below h_min while its error hardly fell with it blames forces that
    /// jump, unless the component that held the test was held at the rounding floor: then
    /// the error is rounding, and the fix is atol.
    #[test]
    fn an_error_that_does_not_shrink_at_the_rounding_floor_is_called_rounding() {
        let held = |set_by| {
            Some(Box::new(HeldBy {
                component: "the velocity of q[0] (a)".into(),
                value: 2.85e-3,
                error: -1.41e-13,
                tolerance: 3.97e-14,
                set_by,
                start: Some(1100.0),
            }))
        };
        let text = |set_by| {
            Failure::StepTooSmall {
                h_min: 1e-12,
                held_by: held(set_by),
                given: false,
                jump: Some(0.0),
                near_change_point: None,
            }
            .to_string()
        };
        let rounding = text("rounding");
        assert!(rounding.contains("as rounding errors do"), "{rounding}");
        assert!(
            rounding.contains("raise atol to at least that"),
            "{rounding}"
        );
        assert!(!rounding.contains("not smooth"), "{rounding}");
        for set_by in ["atol", "rtol"] {
            let jump = text(set_by);
            assert!(jump.contains("the forces are likely not smooth"), "{jump}");
            assert!(jump.contains(&format!("set by {set_by}")), "{jump}");
        }
    }

    #[test]
    fn short_numbers_have_ten_significant_digits_at_most() {
        assert_eq!(short(0.23942707429373464), "0.2394270743");
        assert_eq!(short(2.5), "2.5");
        assert_eq!(short(10.0), "10");
        assert_eq!(short(-1.0), "-1");
        assert_eq!(short(0.0), "0");
        assert_eq!(
            short(3.636924290476571e-2),
            "0.03636924290".trim_end_matches('0')
        );
        assert_eq!(short(1.5e-7), "1.5e-7");
        assert_eq!(short(1.234567890123e9), "1.23456789e9");
        assert_eq!(short(f64::NAN), "NaN");
    }
}
