//! From the options to the running scheme: the `Stepper` of a `Scheme`, and the constraint
//! method it runs.

use super::constrained::Mode;
use super::stepper::Stepper;
use super::{bdf, chebyshev, dopri5, explicit, midpoint, newmark, radau};
use crate::error::Failure;
use crate::options::{ConstraintMethod, Scheme};

/// The constraint method a scheme runs: `Auto` resolved, unsupported pairs refused.
pub(super) fn constraint_mode(
    method: ConstraintMethod,
    scheme: &Scheme,
    adaptive: bool,
) -> Result<Mode, Failure> {
    // without numerical damping, index 3 and step control do not go together
    let no_damping = scheme.spectral_radius_at_infinity() == Some(1.0);
    let undamped = adaptive && no_damping;
    Ok(match method {
        // the damped members of the Newmark family at index 3, Radau only on request. Index 2
        // follows rtol but costs more for the same digits in (q, qd) (`examples/
        // work_precision.rs`: fastlink, 3 digits, gen-α 60 ms at index 2 against 18 ms at
        // index 3, 5 digits 574 ms against 40 ms; four-bar, 3 digits, 6.6 ms against 4.7 ms).
        // The undamped members (trapezoidal Newmark, ρ∞ = 1) diverge at index 3 on fast loops
        // even at fixed steps (slider-crank at h ≥ 1 ms) and take Projection
        ConstraintMethod::Auto if scheme.spectral_radius_at_infinity().is_some() && !no_damping => {
            Mode::Index3
        }
        ConstraintMethod::Auto | ConstraintMethod::Projection => Mode::Projection,
        ConstraintMethod::Index3 if !scheme.solves_index3() => {
            return Err(Failure::ConstraintsUnsupported {
                scheme: scheme.name(),
                method: "index 3",
                supported: INDEX3_SCHEMES,
            });
        }
        ConstraintMethod::Index3 if undamped => {
            return Err(Failure::ConstraintsUnsupported {
                scheme: scheme.name(),
                method: "index 3 with adaptive steps",
                supported: "without numerical damping (ρ∞ = 1) the multipliers λ and the accelerations oscillate from step to step at index 3 (Cardona & Géradin 1989), which defeats the error estimate: use gen-alpha with ρ∞ < 1 or hht, fixed steps, or Projection",
            });
        }
        ConstraintMethod::Index3 => Mode::Index3,
        ConstraintMethod::Index2 if !scheme.solves_index2() => {
            return Err(Failure::ConstraintsUnsupported {
                scheme: scheme.name(),
                method: "stabilized index 2",
                supported: INDEX2_SCHEMES,
            });
        }
        ConstraintMethod::Index2 if undamped => {
            return Err(Failure::ConstraintsUnsupported {
                scheme: scheme.name(),
                method: "stabilized index 2 with adaptive steps",
                supported: "without numerical damping (ρ∞ = 1) λ and the accelerations of fast loops oscillate from step to step, which defeats the error estimate: use gen-alpha with ρ∞ < 1 or hht, fixed steps, or Projection",
            });
        }
        ConstraintMethod::Index2 => Mode::Index2,
        ConstraintMethod::Baumgarte { alpha, beta } => Mode::Baumgarte { alpha, beta },
        ConstraintMethod::Partitioning => Mode::Partitioning,
    })
}

/// The schemes that solve the index-3 equations, for messages.
const INDEX3_SCHEMES: &str = "index-3 constraints are solved by gen-alpha, hht, newmark, radau3 and radau5; every scheme takes them with Projection, Baumgarte or Partitioning";

/// The schemes that solve the stabilized index-2 equations, for messages.
const INDEX2_SCHEMES: &str = "the stabilized index-2 form is solved by gen-alpha, hht, newmark, radau3 and radau5; every scheme takes the constraints with Projection, Baumgarte or Partitioning";

pub(super) fn stepper_for(scheme: &Scheme, n: usize) -> Box<dyn Stepper> {
    match *scheme {
        Scheme::ExplicitEuler => Box::new(explicit::Explicit::euler(n)),
        Scheme::Rk4 => Box::new(explicit::Explicit::rk4(n)),
        Scheme::Rkc => Box::new(chebyshev::Chebyshev::new(n)),
        Scheme::Dopri5 => Box::new(dopri5::Dopri5::new(n)),
        Scheme::Newmark(p) => Box::new(newmark::AlphaFamily::newmark(n, p)),
        Scheme::Hht(p) => Box::new(newmark::AlphaFamily::hht(n, p)),
        Scheme::GenAlpha(p) => Box::new(newmark::AlphaFamily::gen_alpha(n, p)),
        Scheme::ImplicitMidpoint => Box::new(midpoint::Midpoint::new(n)),
        Scheme::Bdf(p) => Box::new(bdf::Bdf::new(n, p.max_order)),
        Scheme::Radau3 => Box::new(radau::Radau::radau3(n)),
        Scheme::Radau5 => Box::new(radau::Radau::radau5(n)),
    }
}
