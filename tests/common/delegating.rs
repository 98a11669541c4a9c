//! `delegating_model!`: a hand-written `Model` that wraps a generated one (its field `.0`) and
//! changes some of its methods, the tests' way to give a model a behaviour no `multibody!`
//! model has (a missing derivative, a failure of user code).

/// `impl Model for $wrapper` answering through `self.0`, a `$inner`, every method it must
/// have but `dynamics`, with the wrapper's own items (`dynamics`, the methods it changes, the
/// constants it sets) added.
macro_rules! delegating_model {
    ($wrapper:ty => $inner:ty { $($item:item)* }) => {
        impl mbs::Model for $wrapper {
            type Params = <$inner as mbs::Model>::Params;
            const NQ: usize = <$inner as mbs::Model>::NQ;
            const NU: usize = <$inner as mbs::Model>::NU;
            const NFRAMES: usize = <$inner as mbs::Model>::NFRAMES;
            const NPOINTS: usize = <$inner as mbs::Model>::NPOINTS;
            const NC: usize = <$inner as mbs::Model>::NC;
            $($item)*
            fn info(&self) -> &'static mbs::ModelInfo {
                self.0.info()
            }
            fn params(&self) -> &Self::Params {
                self.0.params()
            }
            fn set_params(&mut self, p: Self::Params) -> Result<(), mbs::ParamError> {
                self.0.set_params(p)
            }
            fn initial_state(&self, q: &mut [f64], qd: &mut [f64]) {
                self.0.initial_state(q, qd)
            }
            fn mass_matrix(&self, t: f64, q: &[f64], m: &mut [f64]) {
                self.0.mass_matrix(t, q, m)
            }
            fn inverse_dynamics(
                &self,
                t: f64,
                q: &[f64],
                qd: &[f64],
                a: &[f64],
                u: &[f64],
                tau: &mut [f64],
            ) {
                self.0.inverse_dynamics(t, q, qd, a, u, tau)
            }
            #[allow(clippy::too_many_arguments)]
            fn tangents(
                &self,
                t: f64,
                q: &[f64],
                qd: &[f64],
                a: &[f64],
                u: &[f64],
                k: &mut [f64],
                c: &mut [f64],
            ) -> Result<(), mbs::ModelError> {
                self.0.tangents(t, q, qd, a, u, k, c)
            }
            fn static_forces(&self, t: f64, q: &[f64], u: &[f64], h: &mut [f64]) {
                self.0.static_forces(t, q, u, h)
            }
            fn input_matrix(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64], b: &mut [f64]) {
                self.0.input_matrix(t, q, qd, u, b)
            }
            fn energy(&self, t: f64, q: &[f64], qd: &[f64]) -> mbs::Energy {
                self.0.energy(t, q, qd)
            }
            fn power(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64]) -> f64 {
                self.0.power(t, q, qd, u)
            }
            fn constraints(&self, t: f64, q: &[f64], phi: &mut [f64]) {
                self.0.constraints(t, q, phi)
            }
            fn constraint_jacobian(&self, t: f64, q: &[f64], b: &mut [f64]) {
                self.0.constraint_jacobian(t, q, b)
            }
            fn constraint_rate(&self, t: f64, q: &[f64], phi_t: &mut [f64]) {
                self.0.constraint_rate(t, q, phi_t)
            }
            fn constraint_bias(&self, t: f64, q: &[f64], qd: &[f64], gamma: &mut [f64]) {
                self.0.constraint_bias(t, q, qd, gamma)
            }
            fn constraint_tangent(&self, t: f64, q: &[f64], lambda: &[f64], k: &mut [f64]) {
                self.0.constraint_tangent(t, q, lambda, k)
            }
            fn frames(&self, t: f64, q: &[f64], out: &mut [mbs::Pose]) {
                self.0.frames(t, q, out)
            }
            fn kinematics(&self, t: f64, q: &[f64], qd: &[f64], out: &mut mbs::Kinematics) {
                self.0.kinematics(t, q, qd, out)
            }
        }
    };
}
