//! An arm turning in the horizontal plane, driven through a gearbox by a DC motor whose
//! current is an extra first-order state, under a PI speed controller sampled at 1 kHz.
//!
//! Mechanics (generated): a uniform bar 0.4 m, 1 kg, hinged at one end about the vertical z
//! axis (gravity along the axis does no work), viscous friction 0.01 N·m·s at the hinge.
//! Electrics (in Rust, [`Motor`]): L di/dt = V − R i − k ω_m, motor torque k i, gear ratio
//! N = 10 (ω_m = N ω, joint torque N k i), with L = 1 mH, R = 1 Ω, k = 0.05 N·m/A.
//! Controller ([`PiSpeed`]): V = Kp e + Ki ∫e on the joint speed error e = ω_ref − ω, the
//! integral by the rectangle rule, V clipped to ±24 V (the integral frozen while clipped).

use mbs::{Effort, Efforts, State};

mbs::multibody! {
    /// A bar turning about the vertical axis, driven by the torque of a motor (`WithEfforts`).
    pub model Arm {
        param l = 0.4; param m = 1.0;
        dof theta = 0.0;
        input voltage;
        body bar { mass = m; inertia = (0, m * l * l / 12, m * l * l / 12); }
        TOG[bar] = Trotz(theta) * Tdisp(l / 2, 0, 0);
        gravity(0, 0, -9.81);
        generalized_force(theta, -0.01 * qd[0]);
    }
}

/// The motor: its current is the extra state, its torque acts on `theta`; the voltage is the
/// model's input `u[0]`.
#[derive(Clone, Debug)]
pub struct Motor {
    /// inductance (H), resistance (Ω), torque and back-emf constant (N·m/A = V·s/rad), gear
    /// ratio
    pub l: f64,
    pub r: f64,
    pub k: f64,
    pub gear: f64,
}

impl Default for Motor {
    fn default() -> Self {
        Motor {
            l: 1e-3,
            r: 1.0,
            k: 0.05,
            gear: 10.0,
        }
    }
}

impl Efforts for Motor {
    const NX: usize = 1;
    const STATE_NAMES: &'static [&'static str] = &["current"];

    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        let i = e.x[0];
        e.generalized_force(0, self.gear * self.k * i);
        Ok(())
    }

    fn state_derivatives(&mut self, e: &Effort, xd: &mut [f64]) -> Result<(), String> {
        let (i, v, w_motor) = (e.x[0], e.u[0], self.gear * e.qd[0]);
        xd[0] = (v - self.r * i - self.k * w_motor) / self.l;
        Ok(())
    }
}

/// A PI speed controller on the joint speed `qd[0]`, output `u[0]` = V, clipped to ±v_max.
#[derive(Clone, Debug)]
pub struct PiSpeed {
    pub set_point: f64,
    pub kp: f64,
    pub ki: f64,
    pub v_max: f64,
    pub period: f64,
    integral: f64,
}

impl PiSpeed {
    pub fn new(set_point: f64, period: f64) -> PiSpeed {
        PiSpeed {
            set_point,
            kp: 2.0,
            ki: 20.0,
            v_max: 24.0,
            period,
            integral: 0.0,
        }
    }
}

impl mbs::Controller for PiSpeed {
    fn sample(&mut self, _t: f64, s: &State, u: &mut [f64]) {
        let e = self.set_point - s.qd[0];
        let v = self.kp * e + self.ki * (self.integral + e * self.period);
        if v.abs() < self.v_max {
            // anti-windup: integrate only while the output is not clipped
            self.integral += e * self.period;
        }
        u[0] = v.clamp(-self.v_max, self.v_max);
    }
}
