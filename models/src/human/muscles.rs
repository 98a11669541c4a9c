//! The legs' muscles: nine Hill-type musculotendon units per leg ([`mbs::muscle`], De Groote
//! et al. 2016's curves and equilibrium) on the paths of OpenSim's gait10dof18musc model.
//!
//! **Sources.** Maximum isometric forces, optimal fibre lengths, tendon slack lengths,
//! pennation angles and activation time constants (10 ms, 40 ms) are gait10dof18musc's
//! (opensim-org/opensim-models, `Models/Gait10dof18musc/gait10dof18musc.osim`, whose
//! muscles are Millard 2012 units; here they are De Groote 2016 units with those
//! parameters). Its path points are declared in the model (`point … on …` in `part Leg`), in
//! the joint frames of the bodies as OpenSim places them, mirrored for the left leg. Three
//! of its conditional via points are treated as follows: the iliopsoas' third point (active
//! for hip flexion in [−90°, 45°], all of walking) and the gastrocnemius' femoral condyle
//! point (active for knee flexion under 45°) are always on the path, so that every length is
//! a smooth function of the coordinates; the rectus femoris' and vasti's femoral points of
//! deep flexion (beyond 84°) are left out. The quadriceps' moving insertions on the tibia
//! (OpenSim's splines of the knee angle, standing in for the patella) are fixed points on
//! this model's patella instead, which moves with the knee: the least-squares fit over knee
//! angles −75°…3° follows OpenSim's points within 1.4 mm
//! (`tests/human_muscles.rs`).

use super::{
    Fourier, GaitReference, Guard, Human, PassiveJoints, TRACKED, Tracking, cycle_start, dof_index,
    last_cycle_rows,
};
use mbs::Model;
use mbs::elements::Path;
use mbs::muscle::{Fibre, MIN_ACTIVATION, MuscleError, Musculotendon};
use mbs::{Effort, Efforts, Kinematics};

/// One muscle of a leg: name, F_max (N), l_opt (m), l_slack (m), α_opt (rad), and its path's
/// points (the model's point names without the leg's index), origin first.
pub struct MuscleData {
    pub name: &'static str,
    pub max_force: f64,
    pub optimal_length: f64,
    pub slack_length: f64,
    pub pennation: f64,
    pub path: &'static [&'static str],
}

const fn muscle(
    name: &'static str,
    [max_force, optimal_length, slack_length, pennation]: [f64; 4],
    path: &'static [&'static str],
) -> MuscleData {
    MuscleData {
        name,
        max_force,
        optimal_length,
        slack_length,
        pennation,
        path,
    }
}

/// The nine muscles of each leg (gait10dof18musc).
pub const MUSCLES: [MuscleData; 9] = [
    muscle(
        "hamstrings",
        [2700.0, 0.109, 0.326, 0.0],
        &["ham_o", "hams_via", "hams_i"],
    ),
    muscle(
        "bifemsh",
        [804.0, 0.173, 0.089, 0.401_425_73],
        &["bfsh_o", "hams_via", "hams_i"],
    ),
    muscle(
        "glut_max",
        [1944.0, 0.147, 0.127, 0.0],
        &["gmax_o", "gmax_via", "gmax_via2", "gmax_i"],
    ),
    muscle(
        "iliopsoas",
        [2342.0, 0.1, 0.16, 0.139_626_34],
        &["ilps_o", "ilps_via", "ilps_via2", "ilps_via3", "ilps_i"],
    ),
    muscle(
        "rect_fem",
        [1169.0, 0.114, 0.31, 0.087_266_46],
        &["rf_o", "rf_i"],
    ),
    muscle(
        "vasti",
        [5000.0, 0.087, 0.136, 0.052_359_88],
        &["vas_o", "vas_via", "vas_i"],
    ),
    muscle(
        "gastroc",
        [2500.0, 0.06, 0.39, 0.296_705_97],
        &["gas_o", "gas_via", "achilles"],
    ),
    muscle(
        "soleus",
        [5137.0, 0.05, 0.25, 0.436_332_31],
        &["sol_o", "achilles"],
    ),
    muscle(
        "tib_ant",
        [3000.0, 0.098, 0.223, 0.087_266_46],
        &["ta_o", "ta_via", "ta_i"],
    ),
];

/// Number of muscles of the model (both legs).
pub const NM: usize = 18;

/// The model's 18 muscles (right leg's nine, then the left's, in [`MUSCLES`]' order), each
/// a unit and its path, and their excitations: constant, or periodic functions of time.
#[derive(Clone, Debug)]
pub struct Muscles {
    pub units: Vec<(Musculotendon, Path)>,
    /// excitation of each unit, in [0, 1], when `pattern` is empty
    pub excitation: Vec<f64>,
    /// each unit's excitation over time (clamped to [`MIN_ACTIVATION`], 1]); empty: the
    /// constant `excitation`
    pub pattern: Vec<Fourier>,
    /// each unit's activation over time that `pattern` produces (clamped alike), for a
    /// run's start; empty: the excitation's
    pub activation_pattern: Vec<Fourier>,
}

impl Muscles {
    /// The units of [`MUSCLES`] on the points of the model `info`, unexcited.
    pub fn new(info: &mbs::ModelInfo) -> Result<Muscles, String> {
        let mut units = Vec::new();
        for k in 0..2 {
            for m in &MUSCLES {
                let mut unit = Musculotendon::new(
                    &format!("{}[{k}]", m.name),
                    m.max_force,
                    m.optimal_length,
                    m.slack_length,
                    m.pennation,
                );
                unit.activation_times = [0.01, 0.04];
                let names: Vec<String> = m.path.iter().map(|p| format!("{p}[{k}]")).collect();
                let names: Vec<&str> = names.iter().map(String::as_str).collect();
                let path = Path::through(info, &names).map_err(|e| e.to_string())?;
                units.push((unit, path));
            }
        }
        Ok(Muscles {
            units,
            excitation: vec![0.0; NM],
            pattern: Vec::new(),
            activation_pattern: Vec::new(),
        })
    }

    /// Unit `i`'s activation at `t` on its excitation's pattern: `activation_pattern`'s
    /// where there is one, else the excitation (at rest on a constant one).
    pub fn activation_at(&self, i: usize, t: f64) -> f64 {
        match self.activation_pattern.get(i) {
            Some(f) => on_series(f, t),
            None => self.excitation_at(i, t),
        }
    }

    /// Unit `i`'s excitation at `t`.
    pub fn excitation_at(&self, i: usize, t: f64) -> f64 {
        match self.pattern.get(i) {
            Some(f) => on_series(f, t),
            None => self.excitation[i],
        }
    }

    /// The index of unit `name` (`"soleus[0]"`).
    pub fn index(&self, name: &str) -> Option<usize> {
        self.units.iter().position(|(u, _)| u.name == name)
    }

    /// Each unit's path length (m) at the kinematics `kin`.
    pub fn lengths(&self, kin: &Kinematics) -> Vec<f64> {
        self.units.iter().map(|(_, p)| p.length(kin).0).collect()
    }

    /// The fibre lengths (normalised) at which every unit is at rest at the kinematics `kin`
    /// with activations `activation`: the muscles' states of a start in equilibrium.
    pub fn equilibrium(
        &self,
        kin: &Kinematics,
        activation: &[f64],
    ) -> Result<Vec<f64>, MuscleError> {
        self.units
            .iter()
            .zip(activation)
            .map(|((u, p), a)| u.equilibrium(p.length(kin).0, *a))
            .collect()
    }
}

/// The coordinates the muscles act on in the sagittal plane (those gait10dof18musc leaves
/// free): hip flexion, knee and ankle of each leg.
pub const MUSCLE_JOINTS: [&str; 6] = [
    "hip_flexion[0]",
    "knee[0]",
    "ankle[0]",
    "hip_flexion[1]",
    "knee[1]",
    "ankle[1]",
];

impl Muscles {
    /// Unit `i`'s tendon force with its fibre at rest at the kinematics `kin` and
    /// activation `a` (N).
    pub fn force_at_rest(&self, i: usize, kin: &Kinematics, a: f64) -> Result<f64, MuscleError> {
        let (u, p) = &self.units[i];
        let l = p.length(kin).0;
        Ok(u.fibre(l, a, u.equilibrium(l, a)?)?.tendon_force)
    }

    /// Each unit's [`Muscles::force_at_rest`] with activations `a`.
    pub fn forces_at_rest(&self, kin: &Kinematics, a: &[f64]) -> Result<Vec<f64>, MuscleError> {
        (0..self.units.len())
            .map(|i| self.force_at_rest(i, kin, a[i]))
            .collect()
    }

    /// Each unit's moment arms −∂l/∂q at `kin` about the coordinates `dofs`:
    /// `arms[unit][k]`.
    fn arms(&self, kin: &Kinematics, dofs: impl Iterator<Item = usize> + Clone) -> Vec<Vec<f64>> {
        let nq = kin.points.first().map_or(0, |p| p.jv.len() / 3);
        let mut g = vec![0.0; nq];
        self.units
            .iter()
            .map(|(_, p)| {
                p.gradient(kin, &mut g);
                dofs.clone().map(|i| -g[i]).collect()
            })
            .collect()
    }

    /// Constant excitations under which the muscles, at rest at the kinematics `kin`,
    /// produce the generalised forces `moments` ((coordinate, N·m)) on those coordinates:
    /// static optimisation, the least Σ (a − `baseline`)² with every activation in
    /// [`MIN_ACTIVATION`, 1] (`baseline`: one per unit; zeros give the classical least Σ a²,
    /// positive values ask for co-contraction), by Newton on the moments (tendon forces linearised in the
    /// activations by differences) with the least-change step and the units that reach a
    /// bound held there. In steady state the activation equals the excitation.
    pub fn excitations_for(
        &self,
        kin: &Kinematics,
        moments: &[(usize, f64)],
        baseline: &[f64],
    ) -> Result<Vec<f64>, String> {
        let floor = MIN_ACTIVATION;
        let arms = self.arms(kin, moments.iter().map(|(i, _)| *i));
        let nj = moments.len();
        let mut a: Vec<f64> = baseline.iter().map(|b| b.clamp(floor, 1.0)).collect();
        let mut held = [false; NM];
        let err = |e: MuscleError| e.to_string();
        for _ in 0..50 {
            let f = self.forces_at_rest(kin, &a).map_err(err)?;
            let delta = 1e-6;
            let up: Vec<f64> = a.iter().map(|x| x + delta).collect();
            let fu = self.forces_at_rest(kin, &up).map_err(err)?;
            let mut r = vec![0.0; nj];
            for (j, (_, tau)) in moments.iter().enumerate() {
                r[j] = tau - (0..NM).map(|m| arms[m][j] * f[m]).sum::<f64>();
            }
            let scale = moments.iter().map(|(_, t)| t.abs()).fold(1.0, f64::max);
            if r.iter().all(|x| x.abs() < 1e-9 * scale) {
                return Ok(a);
            }
            // A Δa = r over the free units, the new a nearest the baseline:
            // a_free = baseline + Aᵀ y with (A Aᵀ) y = r + A (a_free − baseline)
            let col = |m: usize, j: usize| arms[m][j] * (fu[m] - f[m]) / delta;
            let free: Vec<usize> = (0..NM).filter(|m| !held[*m]).collect();
            let mut rhs = r.clone();
            let mut aat = mbs::DMatrix::<f64>::zeros(nj, nj);
            for &m in &free {
                for j in 0..nj {
                    rhs[j] += col(m, j) * (a[m] - baseline[m]);
                    for k in 0..nj {
                        aat[(j, k)] += col(m, j) * col(m, k);
                    }
                }
            }
            let y = aat
                .lu()
                .solve(&mbs::DMatrix::from_column_slice(nj, 1, &rhs))
                .ok_or("the muscles left free cannot produce the moments asked for")?;
            for &m in &free {
                let v: f64 = baseline[m] + (0..nj).map(|j| col(m, j) * y[j]).sum::<f64>();
                if v < floor || v > 1.0 {
                    held[m] = true;
                }
                a[m] = v.clamp(floor, 1.0);
            }
        }
        Err("static optimisation of the excitations did not converge in 50 iterations".into())
    }

    /// Static optimisation with reserves: the activations in [`MIN_ACTIVATION`, 1] that
    /// minimise Σ (a − `baseline`)² + Σ (r / `reserve`)², r the part of each moment the
    /// muscles (at rest at `kin`) leave to a reserve actuator (N·m; `reserve` in N·m: a
    /// reserve of that size costs as much as a unit activated fully beyond its baseline).
    /// Always has a solution, unlike [`Muscles::excitations_for`]: where the muscles cannot
    /// produce the moments, the reserves do. Projected Gauss–Newton, each unit's tension
    /// linearised in its activation by differences. Returns (activations, reserves).
    pub fn excitations_with_reserves(
        &self,
        kin: &Kinematics,
        moments: &[(usize, f64)],
        baseline: &[f64],
        reserve: f64,
    ) -> Result<(Vec<f64>, Vec<f64>), String> {
        let floor = MIN_ACTIVATION;
        let arms = self.arms(kin, moments.iter().map(|(i, _)| *i));
        let err = |e: MuscleError| e.to_string();
        let w = 1.0 / reserve;
        let mut a: Vec<f64> = baseline.iter().map(|b| b.clamp(floor, 1.0)).collect();
        let residual = |f: &[f64]| -> Vec<f64> {
            moments
                .iter()
                .enumerate()
                .map(|(j, (_, tau))| tau - (0..NM).map(|m| arms[m][j] * f[m]).sum::<f64>())
                .collect()
        };
        for _ in 0..100 {
            let f = self.forces_at_rest(kin, &a).map_err(err)?;
            let delta = 1e-6;
            let up: Vec<f64> = a.iter().map(|x| x + delta).collect();
            let fu = self.forces_at_rest(kin, &up).map_err(err)?;
            let r = residual(&f);
            // J[j][m] = ∂(moment j)/∂a_m; normal equations of
            // w² |r − J Δ|² + |a + Δ − b|²: (w² JᵀJ + I) Δ = w² Jᵀ r − (a − b)
            let jac = |j: usize, m: usize| arms[m][j] * (fu[m] - f[m]) / delta;
            let mut lhs = mbs::DMatrix::<f64>::identity(NM, NM);
            let mut rhs = mbs::DMatrix::<f64>::zeros(NM, 1);
            for m in 0..NM {
                rhs[m] = -(a[m] - baseline[m]);
                for (j, rj) in r.iter().enumerate() {
                    rhs[m] += w * w * jac(j, m) * rj;
                    for k in 0..NM {
                        lhs[(m, k)] += w * w * jac(j, m) * jac(j, k);
                    }
                }
            }
            let step = lhs
                .cholesky()
                .ok_or("static optimisation with reserves: singular normal equations")?
                .solve(&rhs);
            let mut moved = 0.0f64;
            for m in 0..NM {
                let v = (a[m] + step[m]).clamp(floor, 1.0);
                moved = moved.max((v - a[m]).abs());
                a[m] = v;
            }
            if moved < 1e-10 {
                break;
            }
        }
        let f = self.forces_at_rest(kin, &a).map_err(err)?;
        Ok((a, residual(&f)))
    }
}

/// A series of excitations or activations at `t`, clamped to [`MIN_ACTIVATION`, 1].
fn on_series(f: &Fourier, t: f64) -> f64 {
    f.value(t).clamp(MIN_ACTIVATION, 1.0)
}

/// Names of the extra states of [`MuscleDriven`] after the passive joints' 17: the 18
/// activations, then the 18 normalised fibre lengths.
const MUSCLE_STATES: [&str; 2 * NM] = [
    "activation:hamstrings[0]",
    "activation:bifemsh[0]",
    "activation:glut_max[0]",
    "activation:iliopsoas[0]",
    "activation:rect_fem[0]",
    "activation:vasti[0]",
    "activation:gastroc[0]",
    "activation:soleus[0]",
    "activation:tib_ant[0]",
    "activation:hamstrings[1]",
    "activation:bifemsh[1]",
    "activation:glut_max[1]",
    "activation:iliopsoas[1]",
    "activation:rect_fem[1]",
    "activation:vasti[1]",
    "activation:gastroc[1]",
    "activation:soleus[1]",
    "activation:tib_ant[1]",
    "fibre:hamstrings[0]",
    "fibre:bifemsh[0]",
    "fibre:glut_max[0]",
    "fibre:iliopsoas[0]",
    "fibre:rect_fem[0]",
    "fibre:vasti[0]",
    "fibre:gastroc[0]",
    "fibre:soleus[0]",
    "fibre:tib_ant[0]",
    "fibre:hamstrings[1]",
    "fibre:bifemsh[1]",
    "fibre:glut_max[1]",
    "fibre:iliopsoas[1]",
    "fibre:rect_fem[1]",
    "fibre:vasti[1]",
    "fibre:gastroc[1]",
    "fibre:soleus[1]",
    "fibre:tib_ant[1]",
];

const PASSIVE_N: usize = TRACKED.len();

/// Every extra state's name: the passive joints' then the muscles'.
const STATES: [&str; PASSIVE_N + 2 * NM] = {
    let mut out = [""; PASSIVE_N + 2 * NM];
    let mut i = 0;
    while i < PASSIVE_N {
        out[i] = super::PASSIVE_STATES[i];
        i += 1;
    }
    while i < PASSIVE_N + 2 * NM {
        out[i] = MUSCLE_STATES[i - PASSIVE_N];
        i += 1;
    }
    out
};

/// The model driven by its muscles: passive joint moments ([`PassiveJoints`], 17 states)
/// and the 18 muscles with their activations and fibre lengths (36 states), excitations as
/// inputs ([`Muscles::excitation_at`]), optionally a [`super::Tracking`] of the
/// joints the muscles do not span (through the passive part's `tracking`). A fibre beyond
/// its range stops the run with a typed failure naming the muscle, as the [`Guard`] does for
/// the knee and the feet.
#[derive(Clone, Debug)]
pub struct MuscleDriven {
    pub passive: PassiveJoints,
    pub muscles: Muscles,
}

impl MuscleDriven {
    /// The extra states of a start at `t`, the kinematics `kin` and velocities `qd`:
    /// relaxed passive moments, activations as [`Muscles::activation_at`] gives them (equal
    /// to the excitations unless an activation pattern is set) and fibres at rest.
    pub fn initial_states(&self, t: f64, kin: &Kinematics, qd: &[f64]) -> Result<Vec<f64>, String> {
        let mut x = self.passive.relaxed(qd);
        let a: Vec<f64> = (0..NM).map(|i| self.muscles.activation_at(i, t)).collect();
        x.extend_from_slice(&a);
        let fibres = self
            .muscles
            .equilibrium(kin, &a)
            .map_err(|e| e.to_string())?;
        x.extend(fibres);
        Ok(x)
    }

    /// The state of a run on the muscles from the body's (`q`, `qd`) at `t`: the extra
    /// states of [`MuscleDriven::initial_states`] after the velocities, their coordinates'
    /// part zero.
    pub fn start(
        &self,
        model: &Human,
        t: f64,
        mut q: Vec<f64>,
        mut qd: Vec<f64>,
    ) -> Result<(Vec<f64>, Vec<f64>), String> {
        let mut kin = Kinematics::new::<Human>();
        model.kinematics(t, &q, &qd, &mut kin);
        let x = self.initial_states(t, &kin, &qd)?;
        q.resize(q.len() + x.len(), 0.0);
        qd.extend(x);
        Ok((q, qd))
    }

    /// The moments asked of the muscles at [`MUSCLE_JOINTS`] when `torques` ((coordinate,
    /// N·m), a tracking's) hold the body at `q`: each joint's torque less its passive elastic
    /// moment.
    fn moments_asked(
        &self,
        info: &mbs::ModelInfo,
        torques: &[(usize, f64)],
        q: &[f64],
    ) -> Result<Vec<(usize, f64)>, String> {
        MUSCLE_JOINTS
            .iter()
            .map(|name| {
                let i = dof_index(info, name)?;
                let tau = torques
                    .iter()
                    .find(|(j, _)| *j == i)
                    .ok_or_else(|| format!("`{name}` is not held"))?
                    .1;
                let (_, law) = self
                    .passive
                    .joints
                    .iter()
                    .find(|(j, _)| *j == i)
                    .ok_or_else(|| format!("no passive law for `{name}`"))?;
                Ok((i, tau - law.elastic(q[i])))
            })
            .collect()
    }

    /// The guard of the passive part.
    pub fn guard(&self) -> &Guard {
        &self.passive.guard
    }

    /// Unit `i`'s fibre and tendon at the state in `e`.
    pub fn fibre(&self, e: &Effort, i: usize) -> Result<Fibre, String> {
        let (unit, path) = &self.muscles.units[i];
        let (a, lm) = (e.x[PASSIVE_N + i], e.x[PASSIVE_N + NM + i]);
        unit.fibre(path.length(e.kin).0, a, lm)
            .map_err(|e| e.to_string())
    }
}

impl Efforts for MuscleDriven {
    const NX: usize = PASSIVE_N + 2 * NM;
    const STATE_NAMES: &'static [&'static str] = &STATES;

    /// the muscles pull at their paths' points, which needs no Jacobian
    fn reads_jacobians(&self) -> bool {
        self.passive.reads_jacobians()
    }

    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        self.passive.efforts(e)?;
        for i in 0..NM {
            // a fibre beyond its range rejects the state: a Newton iteration's trial state
            // can overshoot where the motion never goes (a smaller step is tried; the run
            // stops typed, `EffortRejected`, where the motion itself goes there)
            let f = self.fibre(e, i).map_err(|m| e.reject(m))?;
            self.muscles.units[i].1.apply(e, f.tendon_force);
        }
        Ok(())
    }

    fn state_derivatives(&mut self, e: &Effort, xd: &mut [f64]) -> Result<(), String> {
        self.passive.state_derivatives(e, &mut xd[..PASSIVE_N])?;
        for i in 0..NM {
            let a = e.x[PASSIVE_N + i];
            xd[PASSIVE_N + i] = self.muscles.units[i]
                .0
                .activation_rate(self.muscles.excitation_at(i, e.t), a);
            xd[PASSIVE_N + NM + i] = self.fibre(e, i)?.length_rate;
        }
        Ok(())
    }
}

/// The muscles at rest, for statics: the passive joints' elastic moments, the tracking of
/// the passive part (the joints the muscles do not span) and each muscle's tension with its
/// fibre at rest (ṽ = 0) under its excitation, recomputed at every q; no extra states. The
/// static equilibrium of a model wrapped with it is an equilibrium of the same model under
/// [`MuscleDriven`] with activations equal to the excitations and the fibres at rest.
#[derive(Clone, Debug)]
pub struct MusclesAtRest(pub MuscleDriven);

impl Efforts for MusclesAtRest {
    fn reads_jacobians(&self) -> bool {
        self.0.reads_jacobians()
    }

    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        let MuscleDriven { passive, muscles } = &mut self.0;
        passive.guard.apply(e)?;
        for (i, law) in &passive.joints {
            e.generalized_force(*i, law.elastic(e.q[*i]));
        }
        if let Some(t) = &mut passive.tracking {
            t.efforts(e)?;
        }
        for (i, (_, path)) in muscles.units.iter().enumerate() {
            let f = muscles
                .force_at_rest(i, e.kin, muscles.excitation[i])
                .map_err(|e| e.to_string())?;
            path.apply(e, f);
        }
        Ok(())
    }
}

/// Standing on the muscles (mode 2's start), from [`muscle_stance`].
#[derive(Clone, Debug)]
pub struct MuscleStance {
    /// the muscle-driven efforts, excitations set
    pub driven: MuscleDriven,
    /// the start: coordinates and velocities of the wrapped model (the body at rest, the
    /// extra states' integrals zero, their values: relaxed passive moments, activations
    /// equal to the excitations, fibres at rest)
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    /// the moments asked of the muscles at [`MUSCLE_JOINTS`] (coordinate, N·m)
    pub moments: Vec<(usize, f64)>,
    /// the equilibrium under the muscles, from statics with the fibres at rest
    pub equilibrium: mbs::Equilibrium,
    /// the held body's equilibrium (coordinates), where the moments were asked
    pub held: Vec<f64>,
}

/// Standing on the muscles with constant excitations (mode 2): the body held by stiff
/// spring–dampers on [`GaitReference::still`]`(ankle)` and its static equilibrium (pelvis
/// free, horizontal position and heading locked: at rest the ground's friction is zero, so
/// they are neutral); the moments the holding supplies at hip flexion, knee and ankle, less
/// the passive moments, asked of the muscles by [`Muscles::excitations_for`] with
/// `baseline`; the joints the muscles do not span stay held (gait10dof18musc locks them);
/// then the equilibrium under those excitations by statics with the fibres at rest
/// ([`MusclesAtRest`]).
pub fn muscle_stance(model: &Human, ankle: f64, baseline: &[f64]) -> Result<MuscleStance, String> {
    let info = model.info();
    let n = Human::NQ;
    let reference = GaitReference::still(info, ankle)?;
    let (q0, _) = cycle_start(model, &reference);
    let tracking = Tracking::new(reference, info, 3000.0, 30.0)?;
    let statics = |q0: Vec<f64>| mbs::StaticsOptions {
        q0: Some(q0),
        locked: vec![0, 2, 4],
        tolerance: 1e-8,
        ..Default::default()
    };
    let held = mbs::static_equilibrium(
        &mbs::WithEfforts::new(model.clone(), tracking.clone()),
        &statics(q0),
    )
    .map_err(|e| format!("the held body: {e}"))?;
    let q = held.q;
    let zero = vec![0.0; n];
    let torques: Vec<(usize, f64)> = tracking.torques(0.0, &q, &zero).collect();
    let mut driven = MuscleDriven {
        passive: PassiveJoints::new(info, 0.1, 0.01)?,
        muscles: Muscles::new(info)?,
    };
    let moments = driven.moments_asked(info, &torques, &q)?;
    let mut kin = Kinematics::new::<Human>();
    model.kinematics(0.0, &q, &zero, &mut kin);
    driven.muscles.excitation = driven.muscles.excitations_for(&kin, &moments, baseline)?;
    let mut rest = tracking;
    rest.release(info, &MUSCLE_JOINTS)?;
    driven.passive.tracking = Some(rest);
    let equilibrium = mbs::static_equilibrium(
        &mbs::WithEfforts::new(model.clone(), MusclesAtRest(driven.clone())),
        &statics(q.clone()),
    )
    .map_err(|e| format!("the body on its muscles: {e}"))?;
    let (qs, qds) = driven.start(model, 0.0, equilibrium.q.clone(), zero)?;
    Ok(MuscleStance {
        driven,
        q: qs,
        qd: qds,
        moments,
        equilibrium,
        held: q,
    })
}

/// The moment (N·m) a reserve actuator supplies at the cost of a unit fully activated, in
/// [`muscle_cycle`]'s static optimisation: small, so the muscles supply what they can.
pub const RESERVE: f64 = 1.0;

/// Mode 1 with muscles: the muscles take over the sagittal joint moments of a tracked
/// cycle, the tracking staying on as reserve actuators (as OpenSim's computed muscle
/// control keeps reserves).
#[derive(Clone, Debug)]
pub struct MuscleCycle {
    /// the muscles with periodic excitations, the passive joints and the tracking
    pub driven: MuscleDriven,
    /// the activations static optimisation found at each instant of the cycle (one row
    /// per instant, [`NM`] columns)
    pub activations: Vec<Vec<f64>>,
    /// at each instant of the cycle, the size |τ| of the moments asked and |r| of the
    /// reserves' part of them (N·m)
    pub moments: Vec<[f64; 2]>,
}

impl MuscleCycle {
    /// The share of the moments asked that the muscles produce over the cycle,
    /// 1 − rms |r| / rms |τ|: instants where little is asked weigh little (a share per
    /// instant, 1 − |r|/|τ|, averaged over a cycle whose moments pass near zero, came out
    /// at −1888 %).
    pub fn share(&self) -> f64 {
        let (asked, left) = self
            .moments
            .iter()
            .fold((0.0, 0.0), |(a, l), [t, r]| (a + t * t, l + r * r));
        if asked > 0.0 {
            1.0 - (left / asked).sqrt()
        } else {
            1.0
        }
    }

    /// The start of a run on the muscles: the tracked cycle's start ([`cycle_start`]) with
    /// the extra states of [`MuscleDriven::initial_states`] (the coordinates' part of them
    /// zero, their values after the velocities).
    pub fn start(&self, model: &Human) -> Result<(Vec<f64>, Vec<f64>), String> {
        let reference = &self
            .driven
            .passive
            .tracking
            .as_ref()
            .ok_or("the cycle's efforts have no tracking")?
            .reference;
        let (q, qd) = cycle_start(model, reference);
        self.driven.start(model, 0.0, q, qd)
    }
}

/// The excitations that let the muscles produce the joint moments of the last cycle of
/// `tr`, a run of `tracking` on `model` sampled uniformly (`Output::Every`): at each output
/// instant the tracking torques at [`MUSCLE_JOINTS`] less the passive elastic moments,
/// asked of the muscles by [`Muscles::excitations_with_reserves`] with `baseline` and
/// reserves costing as much per [`RESERVE`] as a full activation (the fibres at rest: their
/// speed of lengthening is left to the reserves); each unit's activations over the cycle
/// fitted with `harmonics` harmonics, and its excitation the one under which its activation
/// follows that series (the activation dynamics inverted at each instant,
/// [`mbs::muscle::excitation_for_rate`], fitted alike; the activations start on the series).
/// The tracking stays on every joint, as reserves (its feedforward, if any, left out).
pub fn muscle_cycle(
    model: &Human,
    tracking: &Tracking,
    tr: &mbs::Trajectory,
    baseline: &[f64],
    harmonics: usize,
) -> Result<MuscleCycle, String> {
    let info = model.info();
    let n = Human::NQ;
    let period = tracking.reference.period;
    let instants = last_cycle_rows(tr, period, harmonics)?;
    let mut driven = MuscleDriven {
        passive: PassiveJoints::new(info, 0.1, 0.01)?,
        muscles: Muscles::new(info)?,
    };
    let mut kin = Kinematics::new::<Human>();
    let mut activations = Vec::with_capacity(instants.len());
    let mut sizes = Vec::with_capacity(instants.len());
    let mut read = model.clone();
    for &s in &instants {
        let (t, q, qd) = (tr.t[s], &tr.q(s)[..n], &tr.qd(s)[..n]);
        mbs::charts::use_charts_of(&mut read, tr, s);
        read.kinematics(t, q, qd, &mut kin);
        let torques: Vec<(usize, f64)> = tracking.torques(t, q, qd).collect();
        let moments = driven.moments_asked(info, &torques, q)?;
        let (a, reserves) = driven
            .muscles
            .excitations_with_reserves(&kin, &moments, baseline, RESERVE)?;
        let asked = moments.iter().map(|(_, v)| v * v).sum::<f64>().sqrt();
        let left = reserves.iter().map(|v| v * v).sum::<f64>().sqrt();
        activations.push(a);
        sizes.push([asked, left]);
    }
    // the samples begin at `start`, a whole number of periods: the series are in the run's
    // time as they are
    let fitted: Vec<Fourier> = (0..NM)
        .map(|m| {
            let column: Vec<f64> = activations.iter().map(|a| a[m]).collect();
            Fourier::fit(&column, harmonics, period)
        })
        .collect();
    // the excitations that make the activations follow those series: the activation
    // dynamics inverted at each instant, fitted alike
    driven.muscles.pattern = fitted
        .iter()
        .zip(&driven.muscles.units)
        .map(|(f, (unit, _))| {
            let column: Vec<f64> = instants
                .iter()
                .map(|&s| {
                    let [a, rate, _] = f.eval(tr.t[s]);
                    unit.excitation_for_rate(a.clamp(MIN_ACTIVATION, 1.0), rate)
                })
                .collect();
            Fourier::fit(&column, harmonics, period)
        })
        .collect();
    driven.muscles.activation_pattern = fitted;
    // the reserves: the tracking's stiffness and damping, not its feedforward, whose moments
    // the muscles now give
    let mut reserves = tracking.clone();
    reserves.feedforward.clear();
    driven.passive.tracking = Some(reserves);
    Ok(MuscleCycle {
        driven,
        activations,
        moments: sizes,
    })
}

/// The moment arm −∂l/∂q of each unit about coordinate `dof` of the model `info` at `kin`.
pub fn moment_arms(
    muscles: &Muscles,
    info: &mbs::ModelInfo,
    kin: &Kinematics,
    dof: &str,
) -> Result<Vec<f64>, String> {
    let i = dof_index(info, dof)?;
    Ok(muscles
        .arms(kin, std::iter::once(i))
        .into_iter()
        .map(|a| a[0])
        .collect())
}
