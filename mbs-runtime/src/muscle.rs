//! Hill-type musculotendon units: the model of De Groote et al. 2016 (“Evaluation of direct
//! collocation optimal control problem formulations for solving the muscle redundancy
//! problem”, Ann. Biomed. Eng. 44(10)), with the published constants of its curves and of
//! its activation dynamics (the same numbers as SymPy's `physics.biomechanics`
//! `with_defaults`).
//!
//! A unit is a contractile fibre, pennated at α, in series with an elastic tendon, pulling
//! along a path of length l_MT ([`crate::elements::Path`]). Its two first-order states are
//! the activation a and the normalised fibre length l̃_M = l_M / l_opt:
//!
//! - activation: ȧ = (½ + a₀) / (τ_a (½ + 1.5a)) · (e − a) + (½ + 1.5a)(½ − a₀) / τ_d · (e − a),
//!   a₀ = ½ tanh(b (e − a)), b = 10, e the excitation, by default τ_a = 15 ms, τ_d = 60 ms;
//!   ȧ rises with e, so the excitation that makes a follow a given course is found at each
//!   instant from a and ȧ ([`excitation_for_rate`]);
//! - geometry at constant fibre thickness: l_M sin α = l_opt sin α_opt, so the tendon length
//!   is l_T = l_MT − l_M cos α;
//! - equilibrium of fibre and tendon (the fibre-length explicit form): the tendon force
//!   F_T = F_max f_T(l_T / l_slack) balances the fibre along the tendon,
//!   F_T = F_max (a f_L(l̃_M) f_V(ṽ) + f_PE(l̃_M)) cos α, which is solved for the fibre's
//!   normalised lengthening velocity ṽ through the inverse of the force–velocity curve;
//!   then d l̃_M/dt = v_max ṽ with v_max in optimal fibre lengths per second (10).
//!
//! Curves (l̃ normalised lengths, ṽ lengthening velocity in v_max):
//! f_T(l̃_T) = 0.2 exp(33.9367 (l̃_T − 0.995)) − 0.25 (1 at about 4.9 % strain);
//! f_PE(l̃_M) = (exp(4 (l̃_M − 1)/0.6) − 1)/(exp(4) − 1);
//! f_L, a sum of three Gaussians (1 at l̃_M = 1);
//! f_V(ṽ) = −0.318 asinh(−8.149 ṽ − 0.374) + 0.886 (0 at ṽ = −1, about 1 at 0).
//! As published, f_T and f_PE dip slightly below zero at slack (f_T(1) = −0.013, f_PE tends
//! to −0.019), so a slack unit pushes with up to a few percent of F_max (f_T tends to −0.25
//! for a tendon far shorter than its slack length, which the fibre's range keeps away).
//!
//! The force–velocity inversion divides by a f_L: the activation that produces force is
//! floored at [`MIN_ACTIVATION`] (OpenSim's Thelen muscle's minimum activation). A fibre
//! outside its range ([`Musculotendon::fibre_range`]) or shorter than its own thickness is a
//! typed [`MuscleError`].

use thiserror::Error;

/// τ_a, activation time constant (s)
pub const ACTIVATION_TIME: f64 = 0.015;
/// τ_d, deactivation time constant (s)
pub const DEACTIVATION_TIME: f64 = 0.060;
/// b, the smoothing of the switch between activation and deactivation
pub const ACTIVATION_SMOOTHING: f64 = 10.0;
/// the least activation that produces force, in the inversion of the force–velocity curve
pub const MIN_ACTIVATION: f64 = 0.01;

const TENDON: [f64; 4] = [0.2, 0.995, 0.25, 33.936_693_773_116_89];
const PASSIVE: [f64; 2] = [0.6, 4.0];
const ACTIVE: [f64; 12] = [
    0.814, 1.06, 0.162, 0.0633, 0.433, 0.717, -0.0299, 0.2, 0.1, 1.0, 0.354, 0.0,
];
// the published constants (−0.318 is not −1/π)
#[allow(clippy::approx_constant)]
const VELOCITY: [f64; 4] = [-0.318, -8.149, -0.374, 0.886];

/// Normalised tendon force at normalised tendon length l̃_T = l_T / l_slack.
pub fn tendon_force(lt: f64) -> f64 {
    let [c0, c1, c2, c3] = TENDON;
    c0 * (c3 * (lt - c1)).exp() - c2
}

/// The normalised tendon length at which the tendon carries the normalised force `ft`
/// (the inverse of [`tendon_force`], for ft > −0.25).
pub fn tendon_length(ft: f64) -> f64 {
    let [c0, c1, c2, c3] = TENDON;
    ((ft + c2) / c0).ln() / c3 + c1
}

/// Normalised passive fibre force at normalised fibre length.
pub fn passive_force(lm: f64) -> f64 {
    let [e0, k] = PASSIVE;
    ((k * (lm - 1.0) / e0).exp() - 1.0) / (k.exp() - 1.0)
}

/// Normalised active force at normalised fibre length (full activation, isometric).
pub fn active_force(lm: f64) -> f64 {
    ACTIVE
        .chunks_exact(4)
        .map(|c| {
            let z = (lm - c[1]) / (c[2] + c[3] * lm);
            c[0] * (-0.5 * z * z).exp()
        })
        .sum()
}

/// The force–velocity multiplier at normalised lengthening velocity ṽ.
pub fn force_velocity(v: f64) -> f64 {
    let [c0, c1, c2, c3] = VELOCITY;
    c0 * (c1 * v + c2).asinh() + c3
}

/// The normalised lengthening velocity at which the multiplier is `fv` (the inverse of
/// [`force_velocity`]).
pub fn force_velocity_inverse(fv: f64) -> f64 {
    let [c0, c1, c2, c3] = VELOCITY;
    (((fv - c3) / c0).sinh() - c2) / c1
}

/// ȧ at excitation `e` and activation `a`, with activation and deactivation time constants
/// `[τ_a, τ_d]` (s).
pub fn activation_rate(e: f64, a: f64, [tau_a, tau_d]: [f64; 2]) -> f64 {
    let a0 = 0.5 * (ACTIVATION_SMOOTHING * (e - a)).tanh();
    let a1 = 0.5 + 1.5 * a;
    ((0.5 + a0) / (tau_a * a1) + a1 * (0.5 - a0) / tau_d) * (e - a)
}

/// The excitation in [0, 1] under which activation `a` changes at `rate` (1/s): the
/// activation dynamics of [`activation_rate`] inverted, as an excitation pattern that must
/// make the activations follow a given course needs (ȧ rises with the excitation: found by
/// bisection, to 1e-15). Where no excitation gives that rate, the nearest bound, 0 or 1;
/// NaN where `a` or `rate` is NaN (the bisection fell to an excitation of 0 there, a valid
/// looking answer to a question that had none).
pub fn excitation_for_rate(a: f64, rate: f64, times: [f64; 2]) -> f64 {
    if a.is_nan() || rate.is_nan() {
        return f64::NAN;
    }
    let (mut low, mut high) = (0.0, 1.0);
    if activation_rate(low, a, times) >= rate {
        return low;
    }
    if activation_rate(high, a, times) <= rate {
        return high;
    }
    while high - low > 1e-15 {
        let mid = 0.5 * (low + high);
        if activation_rate(mid, a, times) < rate {
            low = mid;
        } else {
            high = mid;
        }
    }
    0.5 * (low + high)
}

/// What a musculotendon unit cannot do.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum MuscleError {
    #[error(
        "muscle `{muscle}`: normalised fibre length {length:.4} is outside the fibre's range [{}, {}]: the path is stretched or shortened beyond what the muscle can follow",
        range[0], range[1]
    )]
    FibreOutOfRange {
        muscle: String,
        length: f64,
        range: [f64; 2],
    },
    #[error(
        "muscle `{muscle}`: the fibre ({length:.4} m) is shorter than its thickness l_opt sin α_opt ({thickness:.4} m)"
    )]
    FibreTooShort {
        muscle: String,
        length: f64,
        thickness: f64,
    },
    #[error(
        "muscle `{muscle}`: no fibre length in its range balances the tendon at musculotendon length {length:.4} m"
    )]
    NoEquilibrium { muscle: String, length: f64 },
    #[error("muscle `{muscle}`: {name} = {value} is invalid: {reason}")]
    InvalidParameter {
        muscle: String,
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error("muscle `{muscle}`: {quantity} = {value} is not finite")]
    NotFinite {
        muscle: String,
        quantity: &'static str,
        value: f64,
    },
    #[error(
        "muscle `{muscle}`: the tendon pulls {ratio:.3e} times what the fibre holds at rest at this length and activation: no fibre speed balances it (a state far from equilibrium: start the fibre at `Musculotendon::equilibrium`)"
    )]
    NoFibreSpeed { muscle: String, ratio: f64 },
}

/// One musculotendon unit's parameters (OpenSim's names and units).
#[derive(Clone, Debug, PartialEq)]
pub struct Musculotendon {
    pub name: String,
    /// F_max (N)
    pub max_isometric_force: f64,
    /// l_opt (m)
    pub optimal_fiber_length: f64,
    /// l_slack (m)
    pub tendon_slack_length: f64,
    /// α_opt (rad)
    pub pennation_angle: f64,
    /// v_max in optimal fibre lengths per second
    pub max_contraction_velocity: f64,
    /// the normalised fibre lengths it may take; beyond, a [`MuscleError::FibreOutOfRange`]
    pub fibre_range: [f64; 2],
    /// [τ_a, τ_d] of the activation dynamics (s)
    pub activation_times: [f64; 2],
}

/// The state of a unit's fibre and tendon at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Fibre {
    /// tension of the tendon, the force the unit pulls its path with (N)
    pub tendon_force: f64,
    /// d l̃_M / dt (1/s)
    pub length_rate: f64,
    /// ṽ, the fibre's lengthening velocity in v_max
    pub velocity: f64,
    /// cos α
    pub cos_pennation: f64,
    /// l̃_T
    pub tendon_length: f64,
}

impl Musculotendon {
    /// A unit with De Groote's defaults: v_max = 10 l_opt/s, τ_a = 15 ms, τ_d = 60 ms; fibre
    /// range [0.4, 1.8] l_opt.
    pub fn new(name: &str, max_force: f64, optimal: f64, slack: f64, pennation: f64) -> Self {
        Musculotendon {
            name: name.to_string(),
            max_isometric_force: max_force,
            optimal_fiber_length: optimal,
            tendon_slack_length: slack,
            pennation_angle: pennation,
            max_contraction_velocity: 10.0,
            fibre_range: [0.4, 1.8],
            activation_times: [ACTIVATION_TIME, DEACTIVATION_TIME],
        }
    }

    /// Checks the parameters: force, lengths, v_max and activation times > 0 and finite,
    /// pennation in [0, π/2), the fibre range within (0, ∞) and increasing.
    /// [`Musculotendon::fibre`] and [`Musculotendon::equilibrium`] call it.
    pub fn validate(&self) -> Result<(), MuscleError> {
        let invalid = |name, value, reason| {
            Err(MuscleError::InvalidParameter {
                muscle: self.name.clone(),
                name,
                value,
                reason,
            })
        };
        let positive = "must be > 0 and finite";
        for (name, value) in [
            ("max_isometric_force", self.max_isometric_force),
            ("optimal_fiber_length", self.optimal_fiber_length),
            ("tendon_slack_length", self.tendon_slack_length),
            ("max_contraction_velocity", self.max_contraction_velocity),
            ("activation_times[0]", self.activation_times[0]),
            ("activation_times[1]", self.activation_times[1]),
        ] {
            if !(value > 0.0 && value.is_finite()) {
                return invalid(name, value, positive);
            }
        }
        let alpha = self.pennation_angle;
        if !(0.0..std::f64::consts::FRAC_PI_2).contains(&alpha) {
            return invalid("pennation_angle", alpha, "must be in [0, π/2) rad");
        }
        let [lo, hi] = self.fibre_range;
        if !(lo > 0.0 && lo.is_finite()) {
            return invalid("fibre_range[0]", lo, positive);
        }
        if !(hi > lo && hi.is_finite()) {
            return invalid(
                "fibre_range[1]",
                hi,
                "must be finite and above fibre_range[0]",
            );
        }
        Ok(())
    }

    fn finite(&self, quantity: &'static str, value: f64) -> Result<(), MuscleError> {
        if value.is_finite() {
            Ok(())
        } else {
            Err(MuscleError::NotFinite {
                muscle: self.name.clone(),
                quantity,
                value,
            })
        }
    }

    /// ȧ at excitation `e` and activation `a`.
    pub fn activation_rate(&self, e: f64, a: f64) -> f64 {
        activation_rate(e, a, self.activation_times)
    }

    /// The excitation under which activation `a` changes at `rate` ([`excitation_for_rate`]).
    pub fn excitation_for_rate(&self, a: f64, rate: f64) -> f64 {
        excitation_for_rate(a, rate, self.activation_times)
    }

    fn thickness(&self) -> f64 {
        self.optimal_fiber_length * self.pennation_angle.sin()
    }

    /// Tendon length (normalised) and cos α at path length `l_mt` and normalised fibre
    /// length `lm`.
    fn geometry(&self, l_mt: f64, lm: f64) -> Result<(f64, f64), MuscleError> {
        let l_m = lm * self.optimal_fiber_length;
        let h = self.thickness();
        if l_m <= h {
            return Err(MuscleError::FibreTooShort {
                muscle: self.name.clone(),
                length: l_m,
                thickness: h,
            });
        }
        let along = (l_m * l_m - h * h).sqrt();
        Ok(((l_mt - along) / self.tendon_slack_length, along / l_m))
    }

    fn check_range(&self, lm: f64) -> Result<(), MuscleError> {
        let [lo, hi] = self.fibre_range;
        if !(lm >= lo && lm <= hi) {
            return Err(MuscleError::FibreOutOfRange {
                muscle: self.name.clone(),
                length: lm,
                range: self.fibre_range,
            });
        }
        Ok(())
    }

    /// The tendon force and the fibre's length rate at path length `l_mt`, activation `a`
    /// and normalised fibre length `lm`.
    pub fn fibre(&self, l_mt: f64, a: f64, lm: f64) -> Result<Fibre, MuscleError> {
        self.validate()?;
        self.finite("musculotendon length", l_mt)?;
        self.finite("activation", a)?;
        self.check_range(lm)?;
        let (lt, cos) = self.geometry(l_mt, lm)?;
        let ft = tendon_force(lt);
        let fv = (ft / cos - passive_force(lm)) / (a.max(MIN_ACTIVATION) * active_force(lm));
        let v = force_velocity_inverse(fv);
        if !v.is_finite() {
            return Err(MuscleError::NoFibreSpeed {
                muscle: self.name.clone(),
                ratio: fv,
            });
        }
        Ok(Fibre {
            tendon_force: self.max_isometric_force * ft,
            length_rate: self.max_contraction_velocity * v,
            velocity: v,
            cos_pennation: cos,
            tendon_length: lt,
        })
    }

    /// The normalised fibre length at which the fibre is at rest (ṽ = 0) at path length
    /// `l_mt` and activation `a`: the start of a run in equilibrium. Found by bisection of
    /// the force balance over the fibre's range.
    pub fn equilibrium(&self, l_mt: f64, a: f64) -> Result<f64, MuscleError> {
        self.validate()?;
        self.finite("musculotendon length", l_mt)?;
        self.finite("activation", a)?;
        let f0 = force_velocity(0.0);
        let a = a.max(MIN_ACTIVATION);
        // tendon force along the fibre minus the fibre's force at rest: decreasing in lm
        let residual = |lm: f64| -> Result<f64, MuscleError> {
            let (lt, cos) = self.geometry(l_mt, lm)?;
            Ok(tendon_force(lt) / cos - a * active_force(lm) * f0 - passive_force(lm))
        };
        let h = self.thickness() / self.optimal_fiber_length;
        let mut lo = self.fibre_range[0].max(h * (1.0 + 1e-9));
        let mut hi = self.fibre_range[1];
        let none = || MuscleError::NoEquilibrium {
            muscle: self.name.clone(),
            length: l_mt,
        };
        // NaN on either side (a tendon force beyond f64) is no bracket either
        if !(residual(lo)? >= 0.0 && residual(hi)? <= 0.0) {
            return Err(none());
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if residual(mid)? > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-14 {
                break;
            }
        }
        Ok(0.5 * (lo + hi))
    }
}
