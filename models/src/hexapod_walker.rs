//! hexapod_walker: the 49-body hexapod of [`crate::hexapod`] built to walk: its legs point
//! outward from the hips (left legs along +y, right legs along −y), each of its 18 joints is
//! driven through a gearbox by a DC motor whose armature current is a first-order state, and
//! its feet touch a terrain of the ground plane and boxes.
//!
//! What is generated and what is Rust:
//!
//! - the mechanics (`multibody!` below): the base on a free joint, six legs of eight bodies
//!   (support, thigh, shank, pantograph link and coupler, three motor rotors turning
//!   [`GEAR`] times as fast as their joints, so the rotors' reflected inertia N²J_r is in M),
//!   gravity, and 18 inputs: the motors' voltages;
//! - the drive chain, the terrain contact and the continuous-time PID variant are a
//!   [`mbs::Efforts`] part ([`Drive`]): per joint L di/dt = V − R i − k N q̇, joint torque
//!   N k i η^tanh(P/P₀) (the gearbox's efficiency η on the power P = N k i q̇ flowing to the
//!   joint, 1/η when the joint drives the motor, blended over P₀ = 1 W so the law stays
//!   smooth); the feet's penalty contact with the [`Terrain`] of ground and boxes
//!   ([`mbs::terrain`], the law of the language's `contact`: F_n = pos(k δ − c δ̇) on
//!   penetration δ, regularised Coulomb friction μ F_n v_t/√(|v_t|² + ε²), its default
//!   coefficients those of the standing hexapod but for ε = 2e-2 m/s rather than 1e-2: at
//!   1e-2 the friction's fastest mode, about 1.6e4/s, needs RK4 steps below 0.17 ms, at 2e-2
//!   they may be 0.25 ms, four per control period; a foot under a tangential force F_t
//!   creeps at ε F_t/(μ F_n)); the electrical energy drawn, ∫ Σ pos(V i) dt, as a state;
//! - control ([`Walker`]): a central gait generator (tripod, wave or ripple; step length,
//!   height, period and duty factor) gives every foot a target in the base frame, with the
//!   base's heading and lateral drift corrected by the central controller; the pantograph
//!   leg's inverse kinematics ([`leg_ik`]) turns it into joint targets; a PID per joint
//!   gives the motor's voltage, clipped to ±`v_max`. The real controller is sampled at
//!   1 kHz ([`Walker::sampled`], a [`mbs::Controller`] holding the voltages between samples);
//!   the continuous variant ([`Control::Continuous`]) integrates its integral terms as states.

pub use mbs::terrain::{Block, Terrain};
use mbs::{Effort, Efforts};
use std::f64::consts::PI;

/// Gear ratio of every joint: the rotors of the model turn this many times as fast.
pub const GEAR: f64 = 100.0;

mbs::multibody! {
    /// The hexapod with outward legs and motor voltages as inputs (no contact, no control:
    /// those are Rust, [`Drive`]).
    pub model HexapodWalker {
        param g = 9.81;
        param m_base = 20.0;
        param m_support = 0.5;
        param m_thigh = 0.8;
        param m_shank = 0.6;
        param m_panto = 0.2;
        param m_coupler = 0.1;
        param m_rotor = 0.05;

        let base_ixx = m_base * (0.6 * 0.6 + 0.15 * 0.15) / 12;
        let base_iyy = m_base * (1.0 * 1.0 + 0.15 * 0.15) / 12;
        let base_izz = m_base * (1.0 * 1.0 + 0.6 * 0.6) / 12;
        let i_support = m_support * (0.1 * 0.1 + 0.1 * 0.1) / 12;
        let i_thigh = m_thigh * 0.3 * 0.3 / 12;
        let i_shank = m_shank * 0.4 * 0.4 / 12;
        let i_panto = m_panto * 0.3 * 0.3 / 12;
        let i_coupler = m_coupler * 0.1 * 0.1 / 12;

        dof x = 0.0; dof y = 0.0; dof z = 0.43;
        dof psi = 0.0; dof theta = 0.0; dof phi = 0.0;
        body base { mass = m_base; inertia = (base_ixx, base_iyy, base_izz); }
        TOG[base] = Tfree(x, y, z, psi, theta, phi);

        // One leg, hip at (hx, hy, 0) in the base frame, pointing along the base's yaw0
        // direction: hip yaw a[k], thigh pitch b[k], knee pitch c[k].
        part Leg(k, hx, hy, yaw0) {
            dof a[k] = 0.0; dof b[k] = 0.3; dof c[k] = -0.3;
            input v_a[k]; input v_b[k]; input v_c[k];
            body support[k] { mass = m_support; inertia = (i_support, i_support, i_support); }
            body thigh[k] { mass = m_thigh; inertia = (0, i_thigh, i_thigh); }
            body shank[k] { mass = m_shank; inertia = (i_shank, i_shank, 0); }
            body panto[k] { mass = m_panto; inertia = (0, i_panto, i_panto); }
            body coupler[k] { mass = m_coupler; inertia = (i_coupler, i_coupler, 0); }
            body rotor_a[k] { mass = m_rotor; inertia = (1e-5, 1e-5, 2e-5); }
            body rotor_b[k] { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
            body rotor_c[k] { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
            TOG[support[k]] = TOG[base] * Tdisp(hx, hy, 0) * Trotz(yaw0) * Trotz(a[k]) * Tdisp(0.05, 0, 0);
            TOG[thigh[k]] = TOG[support[k]] * Tdisp(0.05, 0, 0) * Troty(b[k]) * Tdisp(0.15, 0, 0);
            TOG[shank[k]] = TOG[thigh[k]] * Tdisp(0.15, 0, 0) * Troty(c[k]) * Tdisp(0, 0, -0.2);
            TOG[panto[k]] = TOG[support[k]] * Tdisp(0.05, 0, -0.05) * Troty(b[k]) * Tdisp(0.15, 0, 0);
            TOG[coupler[k]] = TOG[thigh[k]] * Tdisp(0.15, 0, 0) * Troty(c[k]) * Tdisp(0, 0, -0.05);
            TOG[rotor_a[k]] = TOG[base] * Tdisp(hx, hy, 0.05) * Trotz(100 * a[k]);
            TOG[rotor_b[k]] = TOG[support[k]] * Tdisp(0, 0.05, 0) * Troty(100 * b[k]);
            TOG[rotor_c[k]] = TOG[thigh[k]] * Tdisp(0, 0.05, 0) * Troty(100 * c[k]);
            point foot[k] on shank[k] at (0, 0, -0.2);
        }
        Leg(0, 0.4, 0.3, PI / 2);    // front left
        Leg(1, 0.4, -0.3, -PI / 2);  // front right
        Leg(2, 0, 0.3, PI / 2);      // middle left
        Leg(3, 0, -0.3, -PI / 2);    // middle right
        Leg(4, -0.4, 0.3, PI / 2);   // rear left
        Leg(5, -0.4, -0.3, -PI / 2); // rear right

        gravity(0, 0, -g);
    }
}

/// Number of legs, of joints (and motors).
pub const LEGS: usize = 6;
pub const JOINTS: usize = 18;
/// Index in q of the first leg joint (after the base's x, y, z, ψ, θ, φ).
pub const FIRST_JOINT: usize = 6;

/// Hip positions in the base frame and the direction each leg points (yaw0).
pub const HIPS: [(f64, f64, f64); LEGS] = [
    (0.4, 0.3, PI / 2.0),
    (0.4, -0.3, -PI / 2.0),
    (0.0, 0.3, PI / 2.0),
    (0.0, -0.3, -PI / 2.0),
    (-0.4, 0.3, PI / 2.0),
    (-0.4, -0.3, -PI / 2.0),
];
/// From the yaw axis to the thigh's pitch axis, thigh and shank (hip to knee, knee to foot).
const HIP_OFFSET: f64 = 0.1;
const THIGH: f64 = 0.3;
const SHANK: f64 = 0.4;

/// A foot position in the base frame, relative to its hip, from the leg's joint angles.
pub fn leg_fk(leg: usize, a: f64, b: f64, c: f64) -> [f64; 3] {
    let rho = HIP_OFFSET + THIGH * b.cos() - SHANK * (b + c).sin();
    let zeta = -THIGH * b.sin() - SHANK * (b + c).cos();
    let yaw = HIPS[leg].2 + a;
    [rho * yaw.cos(), rho * yaw.sin(), zeta]
}

/// Why a foot target cannot be reached.
#[derive(Clone, Debug, PartialEq)]
pub struct Unreachable {
    pub leg: usize,
    pub target: [f64; 3],
}

impl std::fmt::Display for Unreachable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "leg {} cannot reach the foot target [{:.3}, {:.3}, {:.3}] (m, base frame from its hip): the thigh and shank reach {:.2} to {:.2} m from the pitch axis",
            self.leg,
            self.target[0],
            self.target[1],
            self.target[2],
            SHANK - THIGH,
            THIGH + SHANK
        )
    }
}

/// The pantograph leg's inverse kinematics: the joint angles (a, b, c) that put the foot at
/// `p` (base frame, relative to the hip), with the knee above the line hip–foot (c from
/// sin c = (l₁² + l₂² − d²)/(2 l₁ l₂), |c| < π/2), or [`Unreachable`].
pub fn leg_ik(leg: usize, p: [f64; 3]) -> Result<[f64; 3], Unreachable> {
    let yaw = p[1].atan2(p[0]);
    let mut a = yaw - HIPS[leg].2;
    a = (a + PI).rem_euclid(2.0 * PI) - PI;
    let rho = p[0].hypot(p[1]) - HIP_OFFSET;
    let zeta = p[2];
    let d2 = rho * rho + zeta * zeta;
    let s = (THIGH * THIGH + SHANK * SHANK - d2) / (2.0 * THIGH * SHANK);
    if !(-1.0..=1.0).contains(&s) || !s.is_finite() {
        return Err(Unreachable { leg, target: p });
    }
    let c = s.asin();
    // ρ + i(−ζ) = (A + iB) e^{ib}
    let (aa, bb) = (THIGH - SHANK * c.sin(), SHANK * c.cos());
    let b = (-zeta).atan2(rho) - bb.atan2(aa);
    Ok([a, b, c])
}

/// The gaits of the gait generator: the phase offset of each leg within a cycle and the
/// duty factor (fraction of the cycle a foot is on the ground).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Gait {
    /// two tripods (0, 3, 4) and (1, 2, 5) alternate; duty factor 0.55 by default
    Tripod,
    /// one leg at a time, from the rear forward on each side; duty factor 5/6
    Wave,
    /// the two sides half a cycle apart, each a wave; duty factor 2/3
    Ripple,
}

impl Gait {
    /// The gait named `name` (`tripod`, `wave`, `ripple`).
    pub fn parse(name: &str) -> Option<Gait> {
        match name {
            "tripod" => Some(Gait::Tripod),
            "wave" => Some(Gait::Wave),
            "ripple" => Some(Gait::Ripple),
            _ => None,
        }
    }

    /// The phase offset of `leg` (fraction of a cycle).
    pub fn offset(self, leg: usize) -> f64 {
        match self {
            Gait::Tripod => [0.0, 0.5, 0.5, 0.0, 0.0, 0.5][leg],
            // lift-offs 1/6 of a cycle apart: rear left, middle left, front left, rear right, …
            Gait::Wave => [4.0, 1.0, 5.0, 2.0, 0.0, 3.0][leg] / 6.0,
            // each side a wave a third of a cycle apart, the right side half a cycle later
            Gait::Ripple => [2.0, 5.0, 4.0, 1.0, 0.0, 3.0][leg] / 6.0,
        }
    }

    /// Its usual duty factor.
    pub fn duty(self) -> f64 {
        match self {
            Gait::Tripod => 0.55,
            Gait::Wave => 5.0 / 6.0,
            Gait::Ripple => 2.0 / 3.0,
        }
    }
}

/// What the gait generator is asked for.
#[derive(Clone, Debug)]
pub struct GaitParams {
    pub gait: Gait,
    /// cycle period (s)
    pub period: f64,
    /// duty factor β (fraction of the period a foot is on the ground)
    pub duty: f64,
    /// forward speed (m/s) and yaw rate (rad/s) asked of the base; the step length is
    /// speed × β × period
    pub speed: f64,
    pub yaw_rate: f64,
    /// height a swinging foot is lifted to (m)
    pub step_height: f64,
    /// the feet's neutral distance out from the hip and depth below it (m): the base height
    /// above flat ground
    pub reach: f64,
    pub height: f64,
    /// time standing still before the first step (s)
    pub start: f64,
    /// central controller: heading (1/s) and lateral drift (1/s) correction gains
    pub heading_gain: f64,
    pub lateral_gain: f64,
}

impl GaitParams {
    /// Defaults for `gait` at `speed` m/s.
    pub fn new(gait: Gait, speed: f64) -> GaitParams {
        GaitParams {
            gait,
            period: match gait {
                Gait::Tripod => 1.0,
                Gait::Wave => 2.0,
                Gait::Ripple => 1.5,
            },
            duty: gait.duty(),
            speed,
            yaw_rate: 0.0,
            step_height: 0.05,
            reach: 0.3,
            height: 0.42,
            start: 0.5,
            heading_gain: 1.0,
            lateral_gain: 0.5,
        }
    }

    /// The share of the speed and yaw rate asked at time `t`: 0 before `start`, rising
    /// smoothly (3u² − 2u³) to 1 over the first cycle.
    pub fn ramp(&self, t: f64) -> f64 {
        let u = ((t - self.start) / self.period).clamp(0.0, 1.0);
        u * u * (3.0 - 2.0 * u)
    }

    /// ∫ ramp from `start` to `t` (s): the base's planned travel is speed × this.
    pub fn ramp_integral(&self, t: f64) -> f64 {
        let u = (t - self.start) / self.period;
        if u <= 0.0 {
            0.0
        } else if u <= 1.0 {
            self.period * (u * u * u - 0.5 * u * u * u * u)
        } else {
            self.period * (0.5 + u - 1.0)
        }
    }

    /// Step length (m): how far a stance foot moves back relative to the base.
    pub fn step_length(&self) -> f64 {
        self.speed * self.duty * self.period
    }
}

/// The neutral foot position of `leg` relative to its hip (base frame).
fn neutral(g: &GaitParams, leg: usize) -> [f64; 3] {
    let yaw = HIPS[leg].2;
    [
        (g.reach + HIP_OFFSET) * yaw.cos(),
        (g.reach + HIP_OFFSET) * yaw.sin(),
        -g.height,
    ]
}

/// A foot's position (base frame, from the base's centre) while the base moves at (v, 0)
/// and turns at ω, τ seconds after the middle of its stance: Rz(−ωτ)·p − v τ.
fn stance_point(p: [f64; 3], v: [f64; 2], w: f64, tau: f64) -> [f64; 3] {
    let (s, c) = (-w * tau).sin_cos();
    [
        c * p[0] - s * p[1] - v[0] * tau,
        s * p[0] + c * p[1] - v[1] * tau,
        p[2],
    ]
}

/// The share of a swing at its start (and end) during which the foot only rises (and
/// lowers): it moves across in between.
const ACROSS_START: f64 = 0.2;

/// How wide the gait generator rounds the terrain's edges (m): [`Terrain::planned_height`].
pub const EDGE: f64 = 0.04;

/// The six neutral foot points in the base frame (z = 0).
fn neutral_points(g: &GaitParams) -> [[f64; 3]; LEGS] {
    std::array::from_fn(|leg| {
        let n = neutral(g, leg);
        [HIPS[leg].0 + n[0], HIPS[leg].1 + n[1], 0.0]
    })
}

/// The base's reference height at `pose`: `g.height` above the mean terrain height under
/// the six neutral foot points.
pub fn reference_height(g: &GaitParams, terrain: &Terrain, pose: BasePose) -> f64 {
    let points = neutral_points(g);
    g.height
        + points
            .iter()
            .map(|&p| terrain.planned_height(pose.world(p), EDGE))
            .sum::<f64>()
            / LEGS as f64
}

/// Where the base is: x, y (world) and heading ψ, as the central controller reads them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BasePose {
    pub x: f64,
    pub y: f64,
    pub psi: f64,
}

impl BasePose {
    /// From the base's coordinates in q.
    pub fn of(q: &[f64]) -> BasePose {
        BasePose {
            x: q[0],
            y: q[1],
            psi: q[3],
        }
    }

    /// A point of the base's yawed frame (xy) in world axes.
    fn world(&self, p: [f64; 3]) -> [f64; 2] {
        let (s, c) = self.psi.sin_cos();
        [self.x + c * p[0] - s * p[1], self.y + s * p[0] + c * p[1]]
    }
}

/// The foot targets of every leg (base frame, relative to each hip) at time `t` for a base at
/// `pose` moving at the gait's speed and yaw rate (reached smoothly over the first cycle,
/// [`GaitParams::ramp`]) plus the central controller's corrections `dv` (base frame) and
/// `dw`, over `terrain`: a stance foot stays where it touched down while the base moves on,
/// a swing foot returns on a smooth arc lifted by `step_height` (zero vertical speed at
/// lift-off and touch-down). Until `g.start` the targets are those of the start (a leg in
/// its swing then is held up, the robot standing on the others). Heights
/// follow the terrain under each foot: a foot's target depth below the base is the terrain
/// height there minus the base's reference height, `g.height` above the mean terrain height
/// under the six neutral foot points.
pub fn foot_targets(
    g: &GaitParams,
    terrain: &Terrain,
    pose: BasePose,
    t: f64,
    dv: [f64; 2],
    dw: f64,
) -> [[f64; 3]; LEGS] {
    let mut out = [[0.0; 3]; LEGS];
    let beta = g.duty;
    let ts = beta * g.period;
    let neutral_points = neutral_points(g);
    let ground = |p: [f64; 3]| terrain.planned_height(pose.world(p), EDGE);
    let base_height = reference_height(g, terrain, pose);
    // the base's planned travel and turn since the start, and the corrections' share of a
    // stance foot's motion τ seconds after the middle of its stance
    let plan = |time: f64| {
        (
            g.speed * g.ramp_integral(time),
            g.yaw_rate * g.ramp_integral(time),
        )
    };
    let at = |p: [f64; 3], t_mid: f64, time: f64| {
        let (x0, a0) = plan(t_mid);
        let (x1, a1) = plan(time);
        let tau = time - t_mid;
        let f = stance_point(p, dv, dw, tau);
        let (s, c) = (-(a1 - a0)).sin_cos();
        [c * f[0] - s * f[1] - (x1 - x0), s * f[0] + c * f[1], p[2]]
    };
    // the gait's clock stands still until the start: the targets then are those of the start
    let t = t.max(g.start);
    for (leg, target) in out.iter_mut().enumerate() {
        let p = neutral_points[leg];
        let cycles = (t - g.start) / g.period + g.gait.offset(leg);
        let phase = cycles.rem_euclid(1.0);
        // the start of this leg's current cycle (its last touch-down)
        let t_td = t - phase * g.period;
        let mut foot = if phase < beta {
            // stance: the foot stays where it touched down while the base moves on
            let f = at(p, t_td + ts / 2.0, t);
            [f[0], f[1], ground(f)]
        } else {
            let s = (phase - beta) / (1.0 - beta);
            let t_lo = t_td + ts;
            let t_next = t_td + g.period;
            let from = at(p, t_td + ts / 2.0, t_lo);
            let to = at(p, t_next + ts / 2.0, t_next);
            let (z0, z1) = (ground(from), ground(to));
            // lifted first, across in the middle 60 % of the swing (a foot that lags its
            // target in height would otherwise drag), up to the touch-down height by
            // mid-swing
            let smooth = |x: f64| x * x * (3.0 - 2.0 * x);
            let (across, up) = (
                smooth(((s - ACROSS_START) / (1.0 - 2.0 * ACROSS_START)).clamp(0.0, 1.0)),
                smooth((2.0 * s).min(1.0)),
            );
            let lift = g.step_height * 0.5 * (1.0 - (2.0 * PI * s).cos());
            [
                from[0] + (to[0] - from[0]) * across,
                from[1] + (to[1] - from[1]) * across,
                z0 + (z1 - z0) * up + lift,
            ]
        };
        foot[2] -= base_height;
        *target = [foot[0] - HIPS[leg].0, foot[1] - HIPS[leg].1, foot[2]];
    }
    out
}

/// The motors and gearboxes (every joint alike).
#[derive(Clone, Debug)]
pub struct Motor {
    /// armature resistance (Ω) and inductance (H)
    pub r: f64,
    pub l: f64,
    /// torque constant = back-EMF constant (N·m/A = V·s/rad)
    pub k: f64,
    /// gear ratio (the model's rotors turn this many times as fast: reflected inertia N²J_r)
    pub gear: f64,
    /// gearbox efficiency
    pub eta: f64,
    /// supply voltage: the controller's output is clipped to ±v_max (V)
    pub v_max: f64,
}

impl Default for Motor {
    /// A 150 W brushed motor on a 24 V supply (R 0.6 Ω, L 0.2 mH, k 0.05 N·m/A) through a
    /// 100:1 gearbox of efficiency 0.8: up to 160 N·m and 4.8 rad/s at the joint.
    fn default() -> Self {
        Motor {
            r: 0.6,
            l: 2e-4,
            k: 0.05,
            gear: GEAR,
            eta: 0.8,
            v_max: 24.0,
        }
    }
}

impl Motor {
    /// The joint torque from armature current `i` at joint speed `w`: N k i η^tanh(P/P₀),
    /// P = N k i w the power the motor gives the joint (η when it drives the joint, 1/η when
    /// the joint drives it), P₀ = 1 W.
    pub fn torque(&self, i: f64, w: f64) -> f64 {
        let tau = self.gear * self.k * i;
        // η^x as exp(x ln η): one exponential where `powf` costs about two
        tau * ((tau * w).tanh() * self.eta.ln()).exp()
    }

    /// di/dt at voltage `v`, current `i`, joint speed `w`.
    pub fn current_rate(&self, v: f64, i: f64, w: f64) -> f64 {
        (v - self.r * i - self.k * self.gear * w) / self.l
    }
}

/// PID gains of every joint, from the angle error (rad) to the motor voltage (V).
#[derive(Clone, Debug)]
pub struct Pid {
    pub kp: f64,
    pub ki: f64,
    pub kd: f64,
}

impl Default for Pid {
    /// Kp 1500 V/rad (about 1e4 N·m/rad at the joint at stall), Ki 3000 V/(rad·s), Kd
    /// 50 V·s/rad.
    fn default() -> Self {
        Pid {
            kp: 1500.0,
            ki: 3000.0,
            kd: 50.0,
        }
    }
}

/// The walking controller: gait generator, central controller, leg inverse kinematics and
/// joint PIDs.
#[derive(Clone, Debug)]
pub struct Walker {
    pub gait: GaitParams,
    pub pid: Pid,
    pub motor: Motor,
    /// where the walk starts: x, y and heading ψ of the base
    pub origin: [f64; 3],
    /// what the feet stand on (the controller knows it: the feet's heights follow it)
    pub terrain: Terrain,
}

impl Walker {
    pub fn new(gait: GaitParams) -> Walker {
        Walker {
            gait,
            pid: Pid::default(),
            motor: Motor::default(),
            origin: [0.0; 3],
            terrain: Terrain::default(),
        }
    }

    /// The central controller's corrections at time `t` from the base's x, y, ψ in `q`:
    /// velocity (base frame) and yaw rate added to the gait's, that bring the heading back to
    /// its plan and (walking straight) the base back onto its line. ψ = q\[3\] is the base's
    /// yaw while its chart is the start's; the runtime moves the chart (and q's angles) once
    /// the base has pitched past 60°, fallen. The sampled controller and the continuous PIDs
    /// then hand this the yaw read in the chart ([`Sampled`], [`Drive`]); the walk's figures
    /// read the recorded orientation ([`Walk::base_angles`]).
    pub fn command(&self, t: f64, q: &[f64]) -> ([f64; 2], f64) {
        let g = &self.gait;
        let psi_ref = self.origin[2] + g.yaw_rate * g.ramp_integral(t);
        let wrap = |a: f64| (a + PI).rem_euclid(2.0 * PI) - PI;
        let dw = -g.heading_gain * wrap(q[3] - psi_ref);
        let (s, c) = self.origin[2].sin_cos();
        let (dx, dy) = (q[0] - self.origin[0], q[1] - self.origin[1]);
        let off_line = -s * dx + c * dy;
        let vy = if g.yaw_rate == 0.0 {
            -g.lateral_gain * off_line
        } else {
            0.0
        };
        // from the line's axes to the base's
        let (sd, cd) = wrap(q[3] - self.origin[2]).sin_cos();
        ([vy * sd, vy * cd], dw)
    }

    /// Joint targets (18, in q's order) at time `t` with the central controller reading the
    /// base's pose in `q`.
    pub fn joint_targets(&self, t: f64, q: &[f64]) -> Result<[f64; JOINTS], Unreachable> {
        let (v, w) = self.command(t, q);
        let feet = foot_targets(&self.gait, &self.terrain, BasePose::of(q), t, v, w);
        let mut out = [0.0; JOINTS];
        for (leg, p) in feet.iter().enumerate() {
            let j = leg_ik(leg, *p)?;
            out[3 * leg..3 * leg + 3].copy_from_slice(&j);
        }
        Ok(out)
    }

    /// Targets and their rates (central differences over 0.1 ms) at `t`.
    pub fn targets_and_rates(
        &self,
        t: f64,
        q: &[f64],
    ) -> Result<([f64; JOINTS], [f64; JOINTS]), Unreachable> {
        let dt = 1e-4;
        let now = self.joint_targets(t, q)?;
        let (a, b) = (
            self.joint_targets(t + dt, q)?,
            self.joint_targets(t - dt, q)?,
        );
        let mut rate = [0.0; JOINTS];
        for j in 0..JOINTS {
            rate[j] = (a[j] - b[j]) / (2.0 * dt);
        }
        Ok((now, rate))
    }

    /// The start: the base `gait.height` above flat ground (plus the feet's static sinking,
    /// 1 mm) at `origin`, every foot at its neutral point, at rest; the drive's states
    /// (currents, energy, integrals) zero. `q`, `qd` of the wrapped model (24).
    pub fn initial_state(&self, q: &mut [f64], qd: &mut [f64]) -> Result<(), Unreachable> {
        q.fill(0.0);
        qd.fill(0.0);
        q[0] = self.origin[0];
        q[1] = self.origin[1];
        q[2] = reference_height(&self.gait, &self.terrain, BasePose::of(q)) - 1e-3;
        q[3] = self.origin[2];
        let targets = self.joint_targets(0.0, q)?;
        q[FIRST_JOINT..FIRST_JOINT + JOINTS].copy_from_slice(&targets);
        Ok(())
    }

    /// The PID's voltage of joint `j` before clipping, from the errors.
    fn pid_voltage(&self, e: f64, e_int: f64, e_rate: f64) -> f64 {
        self.pid.kp * e + self.pid.ki * e_int + self.pid.kd * e_rate
    }

    /// The sampled controller (the real one): every `period` s, targets from the gait and
    /// the central controller, then the PIDs (integral by the rectangle rule, frozen while
    /// the voltage is clipped), voltages held until the next sample. `log` receives
    /// (t, voltages) at every sample; an unreachable foot target holds the last voltages
    /// and is recorded in `log`'s failure slot.
    pub fn sampled(&self, period: f64, log: VoltageLog) -> Sampled {
        Sampled {
            walker: self.clone(),
            period,
            integral: [0.0; JOINTS],
            log,
        }
    }
}

/// The walker's sampled controller ([`Walker::sampled`]).
pub struct Sampled {
    walker: Walker,
    period: f64,
    integral: [f64; JOINTS],
    log: VoltageLog,
}

impl Sampled {
    /// One sample at the base pose and joint angles of `q` (ψ = q[3] the base's yaw).
    fn at(&mut self, t: f64, q: &[f64], qd: &[f64], u: &mut [f64]) {
        let walker = &self.walker;
        let mut log = self.log.borrow_mut();
        let (targets, rates) = match walker.targets_and_rates(t, q) {
            Ok(x) => x,
            Err(e) => {
                log.failure.get_or_insert((t, e));
                return;
            }
        };
        let mut v = [0.0; JOINTS];
        for j in 0..JOINTS {
            let (q, qd) = (q[FIRST_JOINT + j], qd[FIRST_JOINT + j]);
            let e = targets[j] - q;
            let raw = walker.pid_voltage(e, self.integral[j] + e * self.period, rates[j] - qd);
            let vmax = walker.motor.v_max;
            v[j] = raw.clamp(-vmax, vmax);
            if raw.abs() <= vmax {
                self.integral[j] += e * self.period;
            }
            u[j] = v[j];
        }
        log.samples.push((t, v));
    }
}

impl mbs::Controller for Sampled {
    /// Reads the base's heading as q\[3\], its yaw in the start's chart.
    fn sample(&mut self, t: f64, s: &mbs::State, u: &mut [f64]) {
        self.at(t, &s.q, &s.qd, u);
    }

    /// Reads the base's heading in its chart: once the base has pitched past 60° the runtime
    /// has moved the chart, and q\[3\] is no longer its yaw.
    fn sample_in_charts(
        &mut self,
        t: f64,
        s: &mbs::State,
        charts: &[[[f64; 3]; 3]],
        u: &mut [f64],
    ) {
        match charts.first().and_then(|c| with_yaw(&s.q, c)) {
            Some(q) => self.at(t, &q, &s.qd, u),
            None => self.at(t, &s.q, &s.qd, u),
        }
    }
}

/// The walker's coordinates.
const NQ: usize = <HexapodWalker as mbs::Model>::NQ;

/// The walker's q (its first [`NQ`] values) with the base's yaw in q[3] when
/// its angles are read in `chart`, another chart than the start's (the runtime moves it once
/// the base has pitched past 60°); `None` in the start's chart, where q[3] is the yaw.
fn with_yaw(q: &[f64], chart: &[[f64; 3]; 3]) -> Option<[f64; NQ]> {
    use mbs::Model;
    use mbs::charts::{joint_rotation, quaternion_near, zyx_angles_of};
    const START: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if *chart == START {
        return None;
    }
    let mut out = [0.0; NQ];
    out.copy_from_slice(&q[..NQ]);
    let base = &HexapodWalker::default().info().rotation_joints[0];
    let r = joint_rotation(chart, base, &out);
    out[3] = zyx_angles_of(quaternion_near(&r, None))[0];
    Some(out)
}

/// What the sampled controller records: the voltages at every sample, and the first foot
/// target it could not reach.
#[derive(Default, Debug)]
pub struct Log {
    pub samples: Vec<(f64, [f64; JOINTS])>,
    pub failure: Option<(f64, Unreachable)>,
}

/// [`Log`] shared between the controller and its caller.
pub type VoltageLog = std::rc::Rc<std::cell::RefCell<Log>>;

/// How the motors' voltages are made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// by the sampled controller, through the model's inputs
    Sampled,
    /// by continuous-time PIDs inside the model, their integrals as states
    Continuous,
}

/// Names of the drive chain's states: currents, the energy drawn, the PIDs' integrals.
const CURRENTS: [&str; JOINTS] = [
    "i:a0", "i:b0", "i:c0", "i:a1", "i:b1", "i:c1", "i:a2", "i:b2", "i:c2", "i:a3", "i:b3", "i:c3",
    "i:a4", "i:b4", "i:c4", "i:a5", "i:b5", "i:c5",
];
const INTEGRALS: [&str; JOINTS] = [
    "int:a0", "int:b0", "int:c0", "int:a1", "int:b1", "int:c1", "int:a2", "int:b2", "int:c2",
    "int:a3", "int:b3", "int:c3", "int:a4", "int:b4", "int:c4", "int:a5", "int:b5", "int:c5",
];
const STATES_SAMPLED: [&str; JOINTS + 1] = {
    let mut s = ["energy"; JOINTS + 1];
    let mut j = 0;
    while j < JOINTS {
        s[j] = CURRENTS[j];
        j += 1;
    }
    s
};
const STATES_CONTINUOUS: [&str; 2 * JOINTS + 1] = {
    let mut s = ["energy"; 2 * JOINTS + 1];
    let mut j = 0;
    while j < JOINTS {
        s[j] = CURRENTS[j];
        s[JOINTS + 1 + j] = INTEGRALS[j];
        j += 1;
    }
    s
};

/// The Rust part of the walking robot: motors, terrain contact and, with `PID = true`, the
/// continuous-time controller. States: 18 currents (A), the electrical energy drawn (J), and
/// with `PID` the 18 integrals of the angle errors (rad·s).
#[derive(Clone, Debug)]
pub struct Drive<const PID: bool> {
    /// the controller (used by the continuous variant)
    pub walker: Walker,
    /// the terrain the feet touch (the controller plans on its own map, `walker.terrain`)
    pub terrain: Terrain,
}

/// The drive of the sampled controller (voltages from the model's inputs).
pub type SampledDrive = Drive<false>;
/// The drive with continuous-time PIDs.
pub type ContinuousDrive = Drive<true>;

/// Index of the energy state among the drive's states.
pub const ENERGY: usize = JOINTS;

impl<const PID: bool> Drive<PID> {
    /// The motors' voltages at the state in `e` and, with the continuous PIDs, the angle
    /// errors their integrals follow (zero for the sampled controller).
    fn voltages(&self, e: &Effort) -> Result<([f64; JOINTS], [f64; JOINTS]), String> {
        let (mut v, mut errors) = ([0.0; JOINTS], [0.0; JOINTS]);
        if !PID {
            v.copy_from_slice(&e.u[..JOINTS]);
            return Ok((v, errors));
        }
        // the base's heading read in its chart
        let yawed = with_yaw(e.q, &e.chart(0));
        let (targets, rates) = self
            .walker
            .targets_and_rates(e.t, yawed.as_ref().map_or(e.q, |q| &q[..]))
            .map_err(|u| u.to_string())?;
        let vmax = self.walker.motor.v_max;
        for j in 0..JOINTS {
            errors[j] = targets[j] - e.q[FIRST_JOINT + j];
            let rate = rates[j] - e.qd[FIRST_JOINT + j];
            v[j] = self
                .walker
                .pid_voltage(errors[j], e.x[JOINTS + 1 + j], rate)
                .clamp(-vmax, vmax);
        }
        Ok((v, errors))
    }
}

impl<const PID: bool> Efforts for Drive<PID> {
    const NX: usize = if PID { 2 * JOINTS + 1 } else { JOINTS + 1 };
    const STATE_NAMES: &'static [&'static str] = if PID {
        &STATES_CONTINUOUS
    } else {
        &STATES_SAMPLED
    };
    const FRAMES: bool = false;

    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        let motor = &self.walker.motor;
        for j in 0..JOINTS {
            let tau = motor.torque(e.x[j], e.qd[FIRST_JOINT + j]);
            e.generalized_force(FIRST_JOINT + j, tau);
        }
        for leg in 0..LEGS {
            self.terrain.apply_point(e, leg);
        }
        Ok(())
    }

    fn state_derivatives(&mut self, e: &Effort, xd: &mut [f64]) -> Result<(), String> {
        let (v, errors) = self.voltages(e)?;
        let motor = &self.walker.motor;
        let mut power = 0.0;
        for j in 0..JOINTS {
            let i = e.x[j];
            xd[j] = motor.current_rate(v[j], i, e.qd[FIRST_JOINT + j]);
            power += (v[j] * i).max(0.0);
        }
        xd[ENERGY] = power;
        if PID {
            xd[JOINTS + 1..].copy_from_slice(&errors);
        }
        Ok(())
    }
}

/// The robot the sampled controller drives, and the one with continuous-time PIDs.
pub type SampledRobot = mbs::WithEfforts<HexapodWalker, SampledDrive>;
pub type ContinuousRobot = mbs::WithEfforts<HexapodWalker, ContinuousDrive>;

/// Period of the real controller (s): 1 kHz.
pub const CONTROL_PERIOD: f64 = 1e-3;

/// A walk: the trajectory (the robot's coordinates, then the drive's states), the work
/// done, the controller's log and, if the run stopped early, why (the trajectory is kept up
/// to there).
pub struct Walk {
    pub walker: Walker,
    /// the terrain the feet touched
    pub terrain: Terrain,
    pub control: Control,
    pub trajectory: mbs::Trajectory,
    pub stats: mbs::Stats,
    pub log: Log,
    pub failure: Option<mbs::SimError>,
    /// wall-clock time of the run (s)
    pub cpu: f64,
}

/// Walks `walker` from its initial state with `scheme` and `options` (their t_end, step
/// control and output; q0 and qd0 are the walker's), its voltages from the 1 kHz sampled
/// controller or the continuous PIDs, on the terrain it knows. An unreachable start is an
/// error; a failure during the run is in [`Walk::failure`], with the trajectory up to it.
pub fn walk(
    walker: &Walker,
    control: Control,
    scheme: mbs::Scheme,
    options: mbs::Options,
) -> Result<Walk, Unreachable> {
    walk_on(walker, &walker.terrain, control, scheme, options)
}

/// [`walk`] on a `terrain` that may differ from the controller's map (`walker.terrain`): a
/// step that is not there, an obstacle it does not know.
pub fn walk_on(
    walker: &Walker,
    terrain: &Terrain,
    control: Control,
    scheme: mbs::Scheme,
    mut options: mbs::Options,
) -> Result<Walk, Unreachable> {
    use mbs::Model;
    let n = HexapodWalker::NQ;
    let nx = match control {
        Control::Sampled => SampledDrive::NX,
        Control::Continuous => ContinuousDrive::NX,
    };
    let (mut q, mut qd) = (vec![0.0; n + nx], vec![0.0; n + nx]);
    walker.initial_state(&mut q[..n], &mut qd[..n])?;
    options.q0 = Some(q);
    options.qd0 = Some(qd);
    let log: VoltageLog = Default::default();
    let start = std::time::Instant::now();
    let result = match control {
        Control::Sampled => {
            let robot = SampledRobot::new(
                HexapodWalker::default(),
                Drive {
                    walker: walker.clone(),
                    terrain: terrain.clone(),
                },
            );
            let inputs = mbs::Inputs::new()
                .controller(CONTROL_PERIOD, walker.sampled(CONTROL_PERIOD, log.clone()));
            mbs::simulate_with(robot, scheme, options, inputs)
        }
        Control::Continuous => {
            let robot = ContinuousRobot::new(
                HexapodWalker::default(),
                Drive {
                    walker: walker.clone(),
                    terrain: terrain.clone(),
                },
            );
            mbs::simulate(robot, scheme, options)
        }
    };
    let cpu = start.elapsed().as_secs_f64();
    let (trajectory, stats, failure) = match result {
        Ok((tr, stats)) => (tr, stats, None),
        Err(e) => {
            let tr = (*e.trajectory).clone();
            let stats = (*e.stats).clone();
            (tr, stats, Some(e))
        }
    };
    let log = std::mem::take(&mut *log.borrow_mut());
    Ok(Walk {
        walker: walker.clone(),
        terrain: terrain.clone(),
        control,
        trajectory,
        stats,
        log,
        failure,
        cpu,
    })
}

/// What a walk shows, from its trajectory.
#[derive(Clone, Debug, Default)]
pub struct Figures {
    /// time simulated (s) and the real-time factor (simulated time / wall-clock time)
    pub t_end: f64,
    pub real_time_factor: f64,
    /// displacement along the start heading and across it (m)
    pub distance: f64,
    pub lateral: f64,
    /// mean forward speed after the first cycle (m/s)
    pub speed: f64,
    /// base heading turned (deg) and the largest heading error after the first cycle (deg)
    pub turned_deg: f64,
    pub heading_error_deg: f64,
    /// largest horizontal travel of a foot during one contact (m) and how many contacts
    pub max_slip: f64,
    pub contacts: usize,
    /// largest |z − z_ref| of the base after the first cycle (m); peak-to-peak pitch and
    /// roll after the first cycle (deg)
    pub height_error: f64,
    pub pitch_range_deg: f64,
    pub roll_range_deg: f64,
    /// electrical energy drawn (J), cost of transport E / (m g d), peak |current| (A),
    /// peak |voltage| (V) and the fraction of samples with a saturated voltage (the cost of
    /// transport is infinite for a walk of less than 1 cm)
    pub energy: f64,
    pub cost_of_transport: f64,
    pub peak_current: f64,
    pub peak_voltage: f64,
    pub saturated: f64,
    /// the lowest foot at the end: its height (m)
    pub lowest_foot_end: f64,
}

impl Walk {
    /// The base pose at output `i`.
    fn q(&self, i: usize) -> &[f64] {
        self.trajectory.q(i)
    }

    /// The base's yaw, pitch and roll (ZYX) at every output, read from its recorded
    /// orientation rather than from q, whose angles are in another chart once the base has
    /// pitched past 60° (the runtime re-centres it); the yaw unwrapped from output to output,
    /// from the start's heading coordinate.
    pub fn base_angles(&self) -> Vec<[f64; 3]> {
        let tr = &self.trajectory;
        let wrap = |a: f64| (a + PI).rem_euclid(2.0 * PI) - PI;
        let mut out: Vec<[f64; 3]> = Vec::with_capacity(tr.len());
        for i in 0..tr.len() {
            // the base's rotation, recorded at every output (the model's one rotation joint)
            let o = tr.orientation(i);
            let mut a = mbs::charts::zyx_angles_of([o[0], o[1], o[2], o[3]]);
            let near = out.last().map_or(tr.q(0)[3], |p| p[0]);
            a[0] = near + wrap(a[0] - near);
            out.push(a);
        }
        out
    }

    /// The figures of the walk.
    pub fn figures(&self) -> Figures {
        use mbs::Model;
        let tr = &self.trajectory;
        let g = &self.walker.gait;
        let n = HexapodWalker::NQ;
        let last = tr.len() - 1;
        let t_end = tr.t[last];
        let after = g.start + g.period;
        let model = HexapodWalker::default();
        let mut kin = mbs::Kinematics::new::<HexapodWalker>();
        let (s0, c0) = self.walker.origin[2].sin_cos();
        let along = |q: &[f64]| {
            let (dx, dy) = (q[0] - self.walker.origin[0], q[1] - self.walker.origin[1]);
            (c0 * dx + s0 * dy, -s0 * dx + c0 * dy)
        };
        let wrap = |a: f64| (a + PI).rem_euclid(2.0 * PI) - PI;
        let mut f = Figures {
            t_end,
            real_time_factor: t_end / self.cpu.max(1e-9),
            ..Figures::default()
        };
        let (d_end, l_end) = along(self.q(last));
        f.distance = d_end;
        f.lateral = l_end;
        let angles = self.base_angles();
        f.turned_deg = (angles[last][0] - self.walker.origin[2]).to_degrees();
        let first = (0..tr.len()).find(|&i| tr.t[i] >= after);
        if let Some(i1) = first {
            let (d1, _) = along(self.q(i1));
            if t_end > tr.t[i1] {
                f.speed = (d_end - d1) / (t_end - tr.t[i1]);
            }
        }
        // contacts and slip, per foot
        let mut touch: [Option<[f64; 2]>; LEGS] = [None; LEGS];
        let (mut pitch, mut roll) = (
            [f64::INFINITY, f64::NEG_INFINITY],
            [f64::INFINITY, f64::NEG_INFINITY],
        );
        let mut model = model.clone();
        for (i, &[yaw, b, c]) in angles.iter().enumerate() {
            let (q, qd) = (&tr.q(i)[..n], &tr.qd(i)[..n]);
            // the base's angles in the chart the run read them in
            mbs::charts::use_charts_of(&mut model, tr, i);
            model.point_kinematics(tr.t[i], q, qd, &mut kin);
            for (leg, slot) in touch.iter_mut().enumerate() {
                let p = kin.points[leg].position;
                if self.terrain.penetration(p).is_some() {
                    let start = *slot.get_or_insert_with(|| {
                        f.contacts += 1;
                        [p[0], p[1]]
                    });
                    f.max_slip = f.max_slip.max((p[0] - start[0]).hypot(p[1] - start[1]));
                } else {
                    *slot = None;
                }
            }
            if tr.t[i] >= after {
                let psi_ref = self.walker.origin[2] + g.yaw_rate * g.ramp_integral(tr.t[i]);
                f.heading_error_deg = f
                    .heading_error_deg
                    .max(wrap(yaw - psi_ref).abs().to_degrees());
                let pose = BasePose {
                    psi: yaw,
                    ..BasePose::of(q)
                };
                let z_ref = reference_height(g, &self.walker.terrain, pose);
                f.height_error = f.height_error.max((q[2] - z_ref).abs());
                pitch = [pitch[0].min(b), pitch[1].max(b)];
                roll = [roll[0].min(c), roll[1].max(c)];
            }
            for j in 0..JOINTS {
                f.peak_current = f.peak_current.max(tr.qd(i)[n + j].abs());
            }
            if i == last {
                f.lowest_foot_end = (0..LEGS)
                    .map(|leg| kin.points[leg].position[2])
                    .fold(f64::INFINITY, f64::min);
            }
        }
        if pitch[1] >= pitch[0] {
            f.pitch_range_deg = (pitch[1] - pitch[0]).to_degrees();
            f.roll_range_deg = (roll[1] - roll[0]).to_degrees();
        }
        f.energy = tr.qd(last)[n + ENERGY];
        let mut m = vec![0.0; n * n];
        model.mass_matrix(0.0, self.q(0), &mut m);
        let weight = m[0] * model.params().g;
        // (no cost of transport for a walk that goes nowhere: a turn on the spot)
        f.cost_of_transport = if d_end.abs() > 0.01 {
            f.energy / (weight * d_end.abs())
        } else {
            f64::INFINITY
        };
        let vmax = self.walker.motor.v_max;
        let mut saturated = 0usize;
        for (_, v) in &self.log.samples {
            for x in v {
                f.peak_voltage = f.peak_voltage.max(x.abs());
                if x.abs() >= vmax {
                    saturated += 1;
                }
            }
        }
        if !self.log.samples.is_empty() {
            f.saturated = saturated as f64 / (self.log.samples.len() * JOINTS) as f64;
        }
        f
    }
}
