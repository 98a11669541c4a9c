//! What drives a model's inputs u: a function of time and controllers sampled at fixed
//! periods.

use super::State;

/// u(t), written into its argument.
pub(crate) type InputFn = Box<dyn FnMut(f64, &mut [f64])>;

/// A controller sampled every period: it reads the state at the sample instant and writes
/// the inputs it drives into `u`, held until its next sample (zero-order hold).
///
/// The angles of a rotation joint (`Tball`, `Tfree`) in `state.q` are read in the joint's
/// chart, which the runtime moves when the joint turns past 60° from it
/// ([`crate::charts`]): a controller that reads a free body's orientation implements
/// [`Controller::sample_in_charts`], which also gets the charts, and reads it with
/// [`crate::charts::joint_rotation`].
pub trait Controller {
    fn sample(&mut self, t: f64, state: &State, u: &mut [f64]);

    /// [`Controller::sample`] with the chart of every rotation joint of the model (rows, in
    /// the order of `ModelInfo::rotation_joints`), the rotation the state's angles are
    /// measured from: `R = chart · Rz(a) · Ry(b) · Rx(c)`. By default it calls `sample`.
    fn sample_in_charts(&mut self, t: f64, state: &State, charts: &[[[f64; 3]; 3]], u: &mut [f64]) {
        let _ = charts;
        self.sample(t, state, u)
    }
}

impl<F: FnMut(f64, &State, &mut [f64])> Controller for F {
    fn sample(&mut self, t: f64, state: &State, u: &mut [f64]) {
        self(t, state, u)
    }
}

/// What drives a model's inputs u: a function of time and sampled controllers. At every
/// evaluation u = (the function's value) + (the outputs the controllers hold, zero until
/// they write them). The integrators stop exactly at every sample instant t₀ + k·T, call the
/// controllers there, and restart from that state (a held output jumps: multistep histories
/// and predictors do not survive it).
#[derive(Default)]
pub struct Inputs {
    pub(super) function: Option<InputFn>,
    pub(super) controllers: Vec<(f64, Box<dyn Controller>)>,
}

impl Inputs {
    pub fn new() -> Inputs {
        Inputs::default()
    }

    /// u(t) (it adds to the controllers' outputs). It is called wherever the run needs u: at
    /// the schemes' stage times, at the times of rejected steps and again at interpolated
    /// output times, so not in the order of time and more than once at some times. It must
    /// be a function of t alone (`FnMut` lets it keep caches); what depends on the run's
    /// past, as a controller's state, belongs in a [`Controller`], which is called once per
    /// sample instant, in order.
    pub fn function(mut self, f: impl FnMut(f64, &mut [f64]) + 'static) -> Inputs {
        self.function = Some(Box::new(f));
        self
    }

    /// A controller sampled every `period` seconds from t₀.
    pub fn controller(mut self, period: f64, c: impl Controller + 'static) -> Inputs {
        self.controllers.push((period, Box::new(c)));
        self
    }
}
