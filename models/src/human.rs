//! Human lower limbs for walking: 14 bodies, 11 joints, 23 coordinates, six contact
//! ellipsoids under each foot.
//!
//! **Sources.** Segment masses, centres of mass, inertias, joint positions and axes are those
//! of OpenSim's gait2392 model (opensim-org/opensim-models, `gait2392_simbody.osim`: a 75 kg,
//! 1.8 m subject, anthropometry after Delp et al. 1990 and Anderson & Pandy 1999), except the
//! toes' third moment of inertia, taken from its sibling gait10dof18musc (gait2392's
//! 0.001 kg·m² breaks the triangle inequality of a rigid body, which mbs refuses); the knee's
//! tibia translates in the femur as natural cubic splines of the knee angle through that
//! model's points (Yamaguchi & Zajac's knee), and the patella moves with the knee along the
//! splines of Rajagopal et al. 2015's patellofemoral joint. Axes as in OpenSim: x forward,
//! y up, z to the right; angles in gait2392's conventions (knee flexion negative, ankle
//! dorsiflexion positive).
//!
//! **Coordinates** (23): the pelvis on a free joint `Tfree(px, py, pz, pa, pb, pc)` (6), the
//! lumbar joint's extension, bending and rotation (3), and per leg k (0 right, 1 left) hip
//! flexion, adduction and rotation, knee, ankle, subtalar and toes (7). Each leg is one
//! instance of `part Leg(k, s)` (s = 1 right, −1 left: the left leg mirrored through the
//! sagittal plane).
//!
//! **Bodies** (14): torso (head, arms and trunk), pelvis, and per leg femur, patella, tibia,
//! talus, calcaneus, toes.
//!
//! **Contact**: six ellipsoids per foot (heel, lateral midfoot, first and fifth metatarsal
//! heads on the calcaneus; hallux and lesser toes on the toes), Hunt–Crossley with Hertz's
//! exponent and regularised Coulomb friction against the ground y = 0. Their placement is
//! this model's own (soles 1 cm below the calcaneus' origin), not gait2392's.
//!
//! **Driving it** (Rust): [`GaitTable`] reads a cycle of joint angles (the stored one is
//! OpenSim's tutorial normal gait, `models/data/normal_gait.tsv`), [`GaitReference`] fits
//! each angle with a Fourier series, and [`Tracking`] (an [`Efforts`] part) holds the joints
//! on the reference with stiff spring–dampers, the pelvis free or its orientation held by
//! residual torques ([`Tracking::pelvis_kp`]); [`GaitReference::grounded`] first makes the
//! cycle consistent with flat ground. [`PassiveJoints`] adds passive joint moments
//! (Anderson's laws, a viscous state per joint), with or without the tracking.
//! [`ground_forces`] recomputes each foot's ground reaction from the kinematics for reports.
//! [`OnTerrain`] wraps any of these parts so the feet's ellipsoids also meet the boxes of a
//! [`Terrain`] (the generated contacts keep the ground).
//! The muscles are in [`muscles`]: [`MuscleDriven`] runs the model on them, [`muscle_stance`]
//! stands it on them.

mbs::multibody! {
    /// Human lower limbs (gait2392 segments, spline knee, patella), pelvis free, feet on
    /// ellipsoids.
    pub model Human {
        // the poses and velocities alone, for the ground checks and the passes over the cycle
        option motion;
        param k_foot = 2e6; param d_foot = 1.0; param mu_foot = 0.8; param eps_foot = 0.01;
        // the tibia's origin in the femur's axes against the knee angle (gait2392)
        fn knee_x(a) = spline(a, [(-2.0944, -0.0032), (-1.74533, 0.00179), (-1.39626, 0.00411),
            (-1.0472, 0.0041), (-0.698132, 0.00212), (-0.349066, -0.001), (-0.174533, -0.0031),
            (0.197344, -0.005227), (0.337395, -0.005435), (0.490178, -0.005574),
            (1.52146, -0.005435), (2.0944, -0.00525)]);
        fn knee_y(a) = spline(a, [(-2.0944, -0.4226), (-1.22173, -0.4082), (-0.523599, -0.399),
            (-0.349066, -0.3976), (-0.174533, -0.3966), (0.159149, -0.395264), (2.0944, -0.396)]);
        // the patella against the knee's flexion b = −knee (Rajagopal 2015)
        fn patella_x(b) = spline(b, [(0.0, 0.0524), (0.174533, 0.0488), (0.349066, 0.0437),
            (0.523599, 0.0371), (0.698132, 0.0296), (0.872665, 0.0216), (1.0472, 0.0136),
            (1.22173, 0.0057), (1.39626, -0.0019), (1.5708, -0.0088), (1.74533, -0.0148),
            (1.91986, -0.0196), (2.0944, -0.0227)]);
        fn patella_y(b) = spline(b, [(0.0, -0.0108), (0.174533, -0.019), (0.349066, -0.0263),
            (0.523599, -0.0322), (0.698132, -0.0367), (0.872665, -0.0395), (1.0472, -0.0408),
            (1.22173, -0.0404), (1.39626, -0.0384), (1.5708, -0.0349), (1.74533, -0.0301),
            (1.91986, -0.0245), (2.0944, -0.0187)]);
        fn patella_angle(b) = spline(b, [(0.0, 0.00113686), (0.174533, -0.00629212),
            (0.349066, -0.105582), (0.523599, -0.253683), (0.698132, -0.414245),
            (0.872665, -0.579047), (1.0472, -0.747244), (1.22173, -0.91799), (1.39626, -1.09044),
            (1.5708, -1.26379), (1.74533, -1.43763), (1.91986, -1.61186), (2.0944, -1.78634)]);

        // the joint axes as the model gives them (8 digits), made unit
        let n_ankle = sqrt(powi(0.10501355, 2) + powi(0.17402245, 2) + powi(0.97912632, 2));
        let n_subtalar = sqrt(powi(0.78717961, 2) + powi(0.60474746, 2) + powi(0.12094949, 2));
        let n_mtp = sqrt(powi(0.5809544, 2) + powi(0.81393611, 2));

        dof px = 0.0; dof py = 0.94; dof pz = 0.0; dof pa = 0.0; dof pb = 0.0; dof pc = 0.0;
        dof lumbar_extension = 0.0; dof lumbar_bending = 0.0; dof lumbar_rotation = 0.0;

        frame pelvis_o;
        TOG[pelvis_o] = Tfree(px, py, pz, pa, pb, pc);
        body pelvis { mass = 11.777; inertia = (0.1028, 0.0871, 0.0579); }
        TOG[pelvis] = TOG[pelvis_o] * Tdisp(-0.0707, 0, 0);
        body torso { mass = 34.2366; inertia = (1.4745, 0.7555, 1.4314); }
        TOG[torso] = TOG[pelvis_o] * Tdisp(-0.1007, 0.0815, 0) * Trotz(lumbar_extension)
            * Trotx(lumbar_bending) * Troty(lumbar_rotation) * Tdisp(-0.03, 0.32, 0);

        part Leg(k, s) {
            dof hip_flexion[k] = 0.0; dof hip_adduction[k] = 0.0; dof hip_rotation[k] = 0.0;
            dof knee[k] = 0.0; dof ankle[k] = 0.0; dof subtalar[k] = 0.0; dof mtp[k] = 0.0;
            frame femur_o[k]; frame tibia_o[k]; frame calcn_o[k]; frame toes_o[k];
            body femur[k] { mass = 9.3014; inertia = (0.1339, 0.0351, 0.1412); }
            body patella[k] { mass = 0.0862; inertia = (2.87e-6, 1.311e-5, 1.311e-5); }
            body tibia[k] { mass = 3.7075; inertia = (0.0504, 0.0051, 0.0511); }
            body talus[k] { mass = 0.1; inertia = (0.001, 0.001, 0.001); }
            body calcn[k] { mass = 1.25; inertia = (0.0014, 0.0039, 0.0041); }
            body toes[k] { mass = 0.2166; inertia = (0.0001, 0.0002, 0.0001); }
            // hip: flexion about z, adduction about x, rotation about y (mirrored on the left)
            TOG[femur_o[k]] = TOG[pelvis_o] * Tdisp(-0.0707, -0.0661, 0.0835 * s)
                * Trotz(hip_flexion[k]) * Trotx(s * hip_adduction[k]) * Troty(s * hip_rotation[k]);
            TOG[femur[k]] = TOG[femur_o[k]] * Tdisp(0, -0.17, 0);
            TOG[tibia_o[k]] = TOG[femur_o[k]] * Tdisp(knee_x(knee[k]), knee_y(knee[k]), 0)
                * Trotz(knee[k]);
            TOG[tibia[k]] = TOG[tibia_o[k]] * Tdisp(0, -0.1867, 0);
            TOG[patella[k]] = TOG[femur_o[k]]
                * Tdisp(-0.00809 + patella_x(-knee[k]), -0.40796 + patella_y(-knee[k]), 0)
                * Trotz(patella_angle(-knee[k])) * Tdisp(0.0018, 0.0264, 0);
            TOG[talus[k]] = TOG[tibia_o[k]] * Tdisp(0, -0.43, 0)
                * Trotn(-0.10501355 * s / n_ankle, -0.17402245 * s / n_ankle, 0.97912632 / n_ankle, ankle[k]);
            TOG[calcn_o[k]] = TOG[talus[k]] * Tdisp(-0.04877, -0.04195, 0.00792 * s)
                * Trotn(0.78717961 * s / n_subtalar, 0.60474746 * s / n_subtalar, -0.12094949 / n_subtalar, subtalar[k]);
            TOG[calcn[k]] = TOG[calcn_o[k]] * Tdisp(0.1, 0.03, 0);
            TOG[toes_o[k]] = TOG[calcn_o[k]] * Tdisp(0.1788, -0.002, 0.00108 * s)
                * Trotn(-0.5809544 * s / n_mtp, 0, 0.81393611 / n_mtp, mtp[k]);
            TOG[toes[k]] = TOG[toes_o[k]] * Tdisp(0.0346, 0.006, -0.0175 * s);
            // the soles 1 cm below the calcaneus' origin
            point heel[k] on calcn_o[k] at (0.035, 0.02, 0);
            point midfoot[k] on calcn_o[k] at (0.1, 0.005, 0.025 * s);
            point meta1[k] on calcn_o[k] at (0.17, 0.005, -0.025 * s);
            point meta5[k] on calcn_o[k] at (0.15, 0.005, 0.035 * s);
            point hallux[k] on toes_o[k] at (0.045, 0.0, -0.02 * s);
            point lesser_toes[k] on toes_o[k] at (0.035, 0.0, 0.02 * s);
            contact(heel[k], ellipsoid = (0.035, 0.03, 0.025), plane = y, k = k_foot, exponent = 1.5, dissipation = d_foot, mu = mu_foot, eps = eps_foot);
            contact(midfoot[k], ellipsoid = (0.03, 0.015, 0.015), plane = y, k = k_foot, exponent = 1.5, dissipation = d_foot, mu = mu_foot, eps = eps_foot);
            contact(meta1[k], ellipsoid = (0.02, 0.015, 0.015), plane = y, k = k_foot, exponent = 1.5, dissipation = d_foot, mu = mu_foot, eps = eps_foot);
            contact(meta5[k], ellipsoid = (0.02, 0.015, 0.012), plane = y, k = k_foot, exponent = 1.5, dissipation = d_foot, mu = mu_foot, eps = eps_foot);
            contact(hallux[k], ellipsoid = (0.025, 0.008, 0.012), plane = y, k = k_foot, exponent = 1.5, dissipation = d_foot, mu = mu_foot, eps = eps_foot);
            contact(lesser_toes[k], ellipsoid = (0.02, 0.008, 0.015), plane = y, k = k_foot, exponent = 1.5, dissipation = d_foot, mu = mu_foot, eps = eps_foot);
            // muscle paths (gait10dof18musc's points in the bodies' joint frames; the
            // quadriceps insert on the patella, see `MUSCLES`)
            point ham_o[k] on pelvis_o at (-0.12596, -0.10257, 0.06944 * s);
            point hams_via[k] on tibia_o[k] at (-0.0301, -0.036, 0.02943 * s);
            point hams_i[k] on tibia_o[k] at (-0.0234, -0.0563, 0.0343 * s);
            point bfsh_o[k] on femur_o[k] at (0.005, -0.2111, 0.0234 * s);
            point gmax_o[k] on pelvis_o at (-0.1349, 0.0176, 0.0563 * s);
            point gmax_via[k] on pelvis_o at (-0.1376, -0.052, 0.0914 * s);
            point gmax_via2[k] on femur_o[k] at (-0.0426, -0.053, 0.0293 * s);
            point gmax_i[k] on femur_o[k] at (-0.0156, -0.1016, 0.0419 * s);
            point ilps_o[k] on pelvis_o at (-0.0647, 0.0887, 0.0289 * s);
            point ilps_via[k] on pelvis_o at (-0.0238, -0.057, 0.0759 * s);
            point ilps_via2[k] on pelvis_o at (-0.0288, -0.0805, 0.0816 * s);
            point ilps_via3[k] on femur_o[k] at (0.0016, -0.0507, 0.0038 * s);
            point ilps_i[k] on femur_o[k] at (-0.0188, -0.0597, 0.0104 * s);
            point rf_o[k] on pelvis_o at (-0.0295, -0.0311, 0.0968 * s);
            point rf_i[k] on patella[k] at (0.0104, 0.0173, 0.0014 * s);
            point vas_o[k] on femur_o[k] at (0.029, -0.1924, 0.031 * s);
            point vas_via[k] on femur_o[k] at (0.0335, -0.2084, 0.0285 * s);
            point vas_i[k] on patella[k] at (0.0041, 0.0216, 0.0018 * s);
            point gas_o[k] on femur_o[k] at (-0.019, -0.3929, -0.0235 * s);
            point gas_via[k] on femur_o[k] at (-0.03, -0.4022, -0.0258 * s);
            point achilles[k] on calcn_o[k] at (0.0, 0.031, -0.0053 * s);
            point sol_o[k] on tibia_o[k] at (-0.0024, -0.1533, 0.0071 * s);
            point ta_o[k] on tibia_o[k] at (0.0179, -0.1624, 0.0115 * s);
            point ta_via[k] on tibia_o[k] at (0.0329, -0.3951, -0.0177 * s);
            point ta_i[k] on calcn_o[k] at (0.1166, 0.0178, -0.0305 * s);
            shape femur[k]: cylinder(0.03, 0.4, axis = y);
            shape tibia[k]: cylinder(0.025, 0.4, axis = y);
            shape calcn[k]: box(0.2, 0.05, 0.08);
            shape toes[k]: box(0.06, 0.02, 0.08);
        }
        Leg(0, 1);
        Leg(1, -1);
        shape pelvis: box(0.12, 0.12, 0.25);
        shape torso: box(0.2, 0.6, 0.35);
        gravity(0, -9.80665, 0);
    }
}

pub mod muscles;
pub use muscles::{
    MUSCLE_JOINTS, MUSCLES, MuscleCycle, MuscleData, MuscleDriven, MuscleStance, Muscles,
    MusclesAtRest, NM, moment_arms, muscle_cycle, muscle_stance,
};

use mbs::terrain::{Block, Ellipsoid, Terrain};
use mbs::{Effort, Efforts, Kinematics, Model};

/// The cycle of normal walking the model follows (see `models/data/normal_gait.tsv`).
const NORMAL_GAIT: &str = include_str!("../data/normal_gait.tsv");

/// A table of samples over one normalised gait cycle: column names and rows (`time` first).
#[derive(Clone, Debug, PartialEq)]
pub struct GaitTable {
    pub names: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl GaitTable {
    /// The OpenSim tutorial's normal walking cycle (51 samples, angles in degrees).
    pub fn normal() -> GaitTable {
        GaitTable::parse(NORMAL_GAIT).expect("the stored table is well formed")
    }

    /// Parses tab- or space-separated text: `#` comments, a header of names, rows of numbers.
    pub fn parse(text: &str) -> Result<GaitTable, String> {
        let mut lines = text
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with('#'));
        let names: Vec<String> = lines
            .next()
            .ok_or("a gait table needs a header line of column names")?
            .split_whitespace()
            .map(String::from)
            .collect();
        let mut rows = Vec::new();
        for (i, l) in lines.enumerate() {
            let row = l
                .split_whitespace()
                .map(|v| {
                    v.parse::<f64>()
                        .map_err(|_| format!("row {}: `{v}` is not a number", i + 1))
                })
                .collect::<Result<Vec<f64>, String>>()?;
            if row.len() != names.len() {
                return Err(format!(
                    "row {} has {} values for {} columns",
                    i + 1,
                    row.len(),
                    names.len()
                ));
            }
            rows.push(row);
        }
        Ok(GaitTable { names, rows })
    }

    /// The samples of column `name`.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let j = self.names.iter().position(|n| n == name)?;
        Some(self.rows.iter().map(|r| r[j]).collect())
    }
}

/// A periodic function as a truncated Fourier series: a₀ + Σₖ aₖ cos(kωt) + bₖ sin(kωt).
#[derive(Clone, Debug, PartialEq)]
pub struct Fourier {
    pub a0: f64,
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    /// ω = 2π / period
    pub omega: f64,
}

impl Fourier {
    /// The least-squares fit with `harmonics` harmonics of `samples` taken uniformly over one
    /// period (the sample at the period's end excluded): on uniform samples the discrete
    /// Fourier sums are the least-squares coefficients.
    pub fn fit(samples: &[f64], harmonics: usize, period: f64) -> Fourier {
        let n = samples.len() as f64;
        let a0 = samples.iter().sum::<f64>() / n;
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for k in 1..=harmonics {
            let (mut ak, mut bk) = (0.0, 0.0);
            for (i, y) in samples.iter().enumerate() {
                let x = std::f64::consts::TAU * (k * i) as f64 / n;
                ak += y * x.cos();
                bk += y * x.sin();
            }
            a.push(2.0 * ak / n);
            b.push(2.0 * bk / n);
        }
        Fourier {
            a0,
            a,
            b,
            omega: std::f64::consts::TAU / period,
        }
    }

    /// The constant `v`.
    pub fn constant(v: f64) -> Fourier {
        Fourier {
            a0: v,
            a: Vec::new(),
            b: Vec::new(),
            omega: 0.0,
        }
    }

    /// Each harmonic at `t`: its frequency kω, its coefficients aₖ, bₖ and cos kωt, sin kωt
    /// (one sine and cosine per call: the harmonics' by the angle-addition recurrence).
    fn harmonics(&self, t: f64) -> impl Iterator<Item = (f64, f64, f64, f64, f64)> + '_ {
        let (s1, c1) = (self.omega * t).sin_cos();
        let (mut s, mut c) = (s1, c1);
        self.a
            .iter()
            .zip(&self.b)
            .enumerate()
            .map(move |(k, (a, b))| {
                let h = ((k + 1) as f64 * self.omega, *a, *b, c, s);
                (s, c) = (s * c1 + c * s1, c * c1 - s * s1);
                h
            })
    }

    /// The value and its first and second time derivatives at `t`.
    pub fn eval(&self, t: f64) -> [f64; 3] {
        let mut out = [self.a0, 0.0, 0.0];
        for (w, a, b, c, s) in self.harmonics(t) {
            out[0] += a * c + b * s;
            out[1] += w * (b * c - a * s);
            out[2] -= w * w * (a * c + b * s);
        }
        out
    }

    /// The value alone at `t` (what [`Fourier::eval`] gives first).
    pub fn value(&self, t: f64) -> f64 {
        self.harmonics(t)
            .fold(self.a0, |v, (_, a, b, c, s)| v + (a * c + b * s))
    }
}

/// The number of coordinate `name` of the model `info` describes.
fn dof_index(info: &mbs::ModelInfo, name: &str) -> Result<usize, String> {
    info.dofs
        .iter()
        .position(|d| *d == name)
        .ok_or_else(|| format!("the model has no coordinate `{name}`"))
}

/// The columns of the gait table that drive the model's coordinates (`None`: held at zero).
const TRACKED: [(&str, Option<&str>); 17] = [
    ("lumbar_extension", Some("lumbar_extension")),
    ("lumbar_bending", Some("lumbar_bending")),
    ("lumbar_rotation", Some("lumbar_rotation")),
    ("hip_flexion[0]", Some("hip_flexion_r")),
    ("hip_adduction[0]", Some("hip_adduction_r")),
    ("hip_rotation[0]", Some("hip_rotation_r")),
    ("knee[0]", Some("knee_angle_r")),
    ("ankle[0]", Some("ankle_angle_r")),
    ("subtalar[0]", None),
    ("mtp[0]", None),
    ("hip_flexion[1]", Some("hip_flexion_l")),
    ("hip_adduction[1]", Some("hip_adduction_l")),
    ("hip_rotation[1]", Some("hip_rotation_l")),
    ("knee[1]", Some("knee_angle_l")),
    ("ankle[1]", Some("ankle_angle_l")),
    ("subtalar[1]", None),
    ("mtp[1]", None),
];

/// The leg joints a gait cycle drives (each leg's coordinates are these with `[0]` or
/// `[1]`): those [`GaitReference::symmetric`] mirrors and [`GaitReference::grounded`]
/// corrects.
const LEG_JOINTS: [&str; 5] = [
    "hip_flexion",
    "hip_adduction",
    "hip_rotation",
    "knee",
    "ankle",
];

/// The joint angles of a gait cycle as smooth periodic functions of time: for each of the
/// model's 17 joint coordinates, a Fourier series fitted to a [`GaitTable`] (degrees
/// converted to radians), the pelvis' orientation likewise.
#[derive(Clone, Debug)]
pub struct GaitReference {
    /// duration of a cycle (s)
    pub period: f64,
    /// (coordinate of the model, its reference)
    pub joints: Vec<(usize, Fourier)>,
    /// pelvis tilt (about z), list (about x) and rotation (about y), gait2392's order
    pub pelvis: [Fourier; 3],
    /// the time of the cycle at t = 0 (0: right heel strike)
    pub offset: f64,
}

impl GaitReference {
    /// The fit of `table` with `harmonics` harmonics, one cycle lasting `period`; the
    /// coordinates found by name in `info`.
    pub fn fit(
        table: &GaitTable,
        info: &mbs::ModelInfo,
        period: f64,
        harmonics: usize,
    ) -> Result<GaitReference, String> {
        // one period of samples: the last row repeats the first cycle's start
        let n = table.rows.len() - 1;
        let series = |name: &str| -> Result<Fourier, String> {
            let col = table
                .column(name)
                .ok_or_else(|| format!("the gait table has no column `{name}`"))?;
            let rad: Vec<f64> = col[..n].iter().map(|d| d.to_radians()).collect();
            Ok(Fourier::fit(&rad, harmonics, period))
        };
        let zero = Fourier::constant(0.0);
        let mut joints = Vec::new();
        for (dof, col) in TRACKED {
            let i = dof_index(info, dof)?;
            let f = match col {
                Some(c) => series(c)?,
                None => zero.clone(),
            };
            joints.push((i, f));
        }
        Ok(GaitReference {
            offset: 0.0,
            period,
            joints,
            pelvis: [
                series("pelvis_tilt")?,
                series("pelvis_list")?,
                series("pelvis_rotation")?,
            ],
        })
    }

    /// The cycle made left–right symmetric, as a normal cycle is and one subject's measured
    /// cycle is not quite (the tutorial's legs differ by degrees half a cycle apart, its
    /// pelvis turns a little more one way than the other): each leg joint of the right leg the mean of
    /// the right one and the left one half a cycle later, the left leg's the right's half a
    /// cycle later; the pelvis' tilt and the lumbar extension of even harmonics only (the
    /// same at each step), the pelvis' list and rotation and the lumbar bending and rotation
    /// of odd harmonics only (of opposite signs at the two steps).
    pub fn symmetric(&self, info: &mbs::ModelInfo) -> Result<GaitReference, String> {
        // harmonic m half a cycle later: × (−1)^m; a[k] is harmonic k + 1
        let later = |f: &Fourier| {
            let mut g = f.clone();
            for k in (0..g.a.len()).step_by(2) {
                g.a[k] = -g.a[k];
                g.b[k] = -g.b[k];
            }
            g
        };
        let mean = |x: &Fourier, y: &Fourier| {
            let mut g = x.clone();
            g.a0 = 0.5 * (x.a0 + y.a0);
            for k in 0..g.a.len() {
                g.a[k] = 0.5 * (x.a[k] + y.a.get(k).copied().unwrap_or(0.0));
                g.b[k] = 0.5 * (x.b[k] + y.b.get(k).copied().unwrap_or(0.0));
            }
            g
        };
        // keeps the harmonics of one parity: even (with the mean) or odd
        let parity = |f: &mut Fourier, even: bool| {
            if !even {
                f.a0 = 0.0;
            }
            for k in 0..f.a.len() {
                if ((k + 1) % 2 == 0) != even {
                    f.a[k] = 0.0;
                    f.b[k] = 0.0;
                }
            }
        };
        let position = |name: &str| -> Result<usize, String> {
            let i = dof_index(info, name)?;
            self.joints
                .iter()
                .position(|(c, _)| *c == i)
                .ok_or_else(|| format!("`{name}` is not in the reference"))
        };
        let mut out = self.clone();
        for joint in LEG_JOINTS {
            let r = position(&format!("{joint}[0]"))?;
            let l = position(&format!("{joint}[1]"))?;
            let right = mean(&self.joints[r].1, &later(&self.joints[l].1));
            out.joints[l].1 = later(&right);
            out.joints[r].1 = right;
        }
        parity(&mut out.pelvis[0], true);
        parity(&mut out.pelvis[1], false);
        parity(&mut out.pelvis[2], false);
        for (name, even) in [
            ("lumbar_extension", true),
            ("lumbar_bending", false),
            ("lumbar_rotation", false),
        ] {
            let k = position(name)?;
            parity(&mut out.joints[k].1, even);
        }
        Ok(out)
    }

    /// A still posture: the anatomical one (every joint at zero) with both ankles
    /// dorsiflexed by `ankle` (rad) and the pelvis tilted forward as much, so that the feet
    /// are flat and the body leans forward as one piece: in the anatomical posture itself
    /// the centre of mass lies just behind the heels' support points.
    pub fn still(info: &mbs::ModelInfo, ankle: f64) -> Result<GaitReference, String> {
        let zero = || Fourier::constant(0.0);
        let mut joints = Vec::new();
        for (dof, _) in TRACKED {
            let i = dof_index(info, dof)?;
            let v = if dof.starts_with("ankle") { ankle } else { 0.0 };
            joints.push((i, Fourier::constant(v)));
        }
        Ok(GaitReference {
            period: 1.0,
            joints,
            pelvis: [Fourier::constant(-ankle), zero(), zero()],
            offset: 0.0,
        })
    }

    /// The reference made consistent with flat ground, a kinematic pass before tracking (as
    /// OpenSim's residual reduction adjusts a subject's kinematics to its model): the legs'
    /// hip, knee and ankle angles get periodic corrections (Fourier series of
    /// `Grounding::harmonics`, the left leg's the right's half a cycle later) found by
    /// Levenberg–Marquardt on least squares over `samples` instants of the cycle, so that
    /// - in double support (`double`) the two feet's lowest points are level;
    /// - in single support the swinging foot's lowest point is above the standing one's by
    ///   `clearance` × sin(π u), u the fraction of the swing (no clearance asked at lift-off
    ///   and touch-down, so the foot leaves and meets the ground without a jump);
    /// - in double support the two feet's lowest points move together: their material
    ///   points' horizontal velocities are equal (neither foot slides on the ground);
    /// - the centre of mass accelerates within ± `max_acceleration` g along each world axis,
    ///   so the ground's force stays within those bounds of weight (vertically: no flight).
    ///   Vertically it is the centre's height above the lower foot; horizontally its
    ///   velocity relative to the standing foot's contact (the mean of the two in double
    ///   support), the momentum's rows of the mass matrix over the mass;
    /// - in single support the ground's force, applied at the standing foot's contact,
    ///   points at the centre of mass (fore–aft over vertical force = the centre's lead
    ///   over the contact / its height: no moment about the centre of mass, the inverted
    ///   pendulum of walking; this is what makes the fore–aft force brake, then propel);
    /// - the walking speed (the standing contact's mean backward speed) stays near the
    ///   uncorrected reference's (a residual per 0.1 m/s, as light as the others);
    /// - the corrections stay small (a penalty, the hips' adduction and rotation twice as
    ///   costly);
    /// - with [`Grounding::pressure`], the centre of pressure the motion needs lies within
    ///   the standing feet's support and the free moment it needs is small.
    ///
    /// A foot's lowest point and its contact are its ellipsoids' support points blended by
    /// a soft minimum over 0.5 mm of height (the hard minimum jumps from ellipsoid to
    /// ellipsoid as the foot rolls, and the pass's result then depended on rounding), with
    /// the pelvis on its reference orientation; the
    /// centre of mass' height is the potential energy over the weight, its fore–aft
    /// position from the mass matrix (the column of the pelvis' rotation about the vertical).
    /// Levenberg–Marquardt, the Jacobian by forward differences shared among the cores,
    /// until ten iterations lower the cost by less than 1e-4 of it (`human_gait` prints the
    /// iterations and the time: 396 and about 10 s on two cores for the normal cycle).
    pub fn grounded(&self, model: &Human, how: &Grounding) -> Result<Grounded, String> {
        let info = model.info();
        let mut joints = [[(0usize, 0usize); 5]; 2];
        for (leg, row) in joints.iter_mut().enumerate() {
            for (j, name) in LEG_JOINTS.iter().enumerate() {
                let i = dof_index(info, &format!("{name}[{leg}]"))?;
                let k = self
                    .joints
                    .iter()
                    .position(|(c, _)| *c == i)
                    .ok_or_else(|| format!("`{name}[{leg}]` is not tracked"))?;
                row[j] = (k, i);
            }
        }
        // the reference's states at the instants, once
        let states = (0..how.samples)
            .map(|s| {
                let t = s as f64 / how.samples as f64 * self.period - self.offset;
                reference_state(model, self, t)
            })
            .collect();
        let mut pass = Pass {
            model,
            states,
            period: self.period,
            joints,
            how,
            feet: Feet::of(info),
            weight: total_mass(model) * G,
            speed: 0.0,
        };
        let nx = 5 * (2 * how.harmonics + 1);
        let mut kin = Kinematics::new::<Human>();
        pass.speed = pass.speed(&pass.samples(&vec![0.0; nx], &mut kin, false));
        let residuals = |x: &[f64]| pass.residuals(x, &mut Kinematics::new::<Human>());
        let (x, iterations) = levenberg_marquardt(nx, &residuals, how.iterations, 1e-6, 1e-3, 1);
        // the corrected reference: each joint's series plus its correction
        let slots: Vec<[usize; 2]> = (0..5).map(|j| [joints[0][j].0, joints[1][j].0]).collect();
        let reference = self.corrected(&slots, &x, how.harmonics);
        let samples = pass.samples(&x, &mut kin, true);
        let (level, clearance, acceleration, slip) = pass.measure(&samples);
        let (pressure_beyond, free_moment) = pass.pressure(&samples);
        let speed = pass.speed(&samples);
        let largest_change = (0..how.samples)
            .flat_map(|s| {
                let phase = s as f64 / how.samples as f64;
                (0..5).flat_map(move |j| [0, 1].map(move |leg| (phase, j, leg)))
            })
            .map(|(phase, j, leg)| pass.correction(&x, j, phase, leg).0.abs())
            .fold(0.0, f64::max);

        Ok(Grounded {
            reference,
            level,
            clearance,
            acceleration,
            slip,
            speed,
            largest_change,
            iterations,
            pressure_beyond,
            free_moment,
        })
    }

    /// This cycle with periodic corrections of some leg joints: for each entry of `slots`,
    /// the indices in [`GaitReference::joints`] of one joint of the right and the left leg,
    /// and 2 `harmonics` + 1 coefficients of `x` (constant, cosines, sines) added to the
    /// right leg's series and to the left leg's half a cycle later (odd harmonics of
    /// opposite sign), so that the cycle stays symmetric.
    fn corrected(&self, slots: &[[usize; 2]], x: &[f64], harmonics: usize) -> GaitReference {
        let mut reference = self.clone();
        let h = harmonics;
        for (j, legs) in slots.iter().enumerate() {
            let c = &x[j * (2 * h + 1)..(j + 1) * (2 * h + 1)];
            for (leg, k) in legs.iter().enumerate() {
                let f = &mut reference.joints[*k].1;
                f.a0 += c[0];
                if f.a.len() < h {
                    f.a.resize(h, 0.0);
                    f.b.resize(h, 0.0);
                }
                for m in 1..=h {
                    // the left leg half a cycle later: odd harmonics change sign
                    let sign = if leg == 1 && m % 2 == 1 { -1.0 } else { 1.0 };
                    f.a[m - 1] += sign * c[m];
                    f.b[m - 1] += sign * c[h + m];
                }
            }
        }
        reference
    }

    /// The largest angle (rad) between the pelvis' orientation along `tr` (a run of
    /// `model`, its first [`Human::NQ`] coordinates read in the charts the run read them in)
    /// and this cycle's reference orientation: how far a run with the pelvis free departs
    /// from the cycle it follows.
    pub fn pelvis_departure(&self, model: &Human, tr: &mbs::Trajectory) -> f64 {
        let Some(pelvis) = model.info().frame_index("pelvis_o") else {
            return f64::NAN;
        };
        let (n, mut model) = (Human::NQ, model.clone());
        let mut poses = vec![mbs::Pose::default(); Human::NFRAMES];
        (0..tr.len())
            .map(|i| {
                mbs::charts::use_charts_of(&mut model, tr, i);
                model.frames(tr.t[i], &tr.q(i)[..n], &mut poses);
                let r = poses[pelvis].rotation;
                let rr = self.pelvis_rotation(tr.t[i]);
                // the angle of R_ref^T R from its trace
                let trace: f64 = (0..3)
                    .map(|a| (0..3).map(|m| rr[a][m] * r[a][m]).sum::<f64>())
                    .sum();
                (0.5 * (trace - 1.0)).clamp(-1.0, 1.0).acos()
            })
            .fold(0.0, f64::max)
    }

    /// Joint `k` of `joints` at `t`: angle, rate, acceleration.
    pub fn joint(&self, k: usize, t: f64) -> [f64; 3] {
        self.joints[k].1.eval(t + self.offset)
    }

    /// The pelvis' rotation matrix at `t`: Rz(tilt) Rx(list) Ry(rotation).
    pub fn pelvis_rotation(&self, t: f64) -> [[f64; 3]; 3] {
        let [a, b, c] = [0, 1, 2].map(|k| self.pelvis[k].value(t + self.offset));
        mul(&mul(&rot(2, a), &rot(0, b)), &rot(1, c))
    }
}

/// Levenberg–Marquardt from x = 0 (`nx` unknowns) on `residuals`, their Jacobian by
/// forward differences of `step` shared among the cores, every `refresh` iterations (in
/// between, Broyden's rank-one updates from each step taken; an iteration that finds no
/// lower cost on an updated Jacobian is followed by differences), the damping starting at
/// `mu`: at most `iterations`, fewer when no step lowers the cost on differences or when ten
/// iterations together lower it by less than 1e-4 of itself (the cost can fall slowly along
/// a valley for a hundred iterations or more, and an earlier stop depends on rounding). The
/// unknowns and the iterations taken.
fn levenberg_marquardt(
    nx: usize,
    residuals: &(dyn Fn(&[f64]) -> Vec<f64> + Sync),
    iterations: usize,
    step: f64,
    mu: f64,
    refresh: usize,
) -> (Vec<f64>, usize) {
    let cost = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let mut x = vec![0.0; nx];
    let mut r = residuals(&x);
    let mut mu = mu;
    let mut taken = 0;
    let mut costs = vec![cost(&r)];
    let (window, tol) = (10, 1e-4);
    // the Jacobian and the iterations since its differences
    let mut jacobian: Option<(mbs::DMatrix<f64>, usize)> = None;
    while taken < iterations {
        taken += 1;
        let m = r.len();
        let (jac, age) = match jacobian.take() {
            Some((jac, age)) if age < refresh.max(1) => (jac, age),
            _ => (differences(nx, residuals, &x, &r, step), 0),
        };
        let jtj = jac.transpose() * &jac;
        let jtr = jac.transpose() * mbs::DMatrix::from_column_slice(m, 1, &r);
        let mut taken_step = None;
        for _ in 0..10 {
            let mut a = jtj.clone();
            for d in 0..nx {
                a[(d, d)] += mu * (1.0 + jtj[(d, d)]);
            }
            let Some(step) = a.lu().solve(&(-&jtr)) else {
                mu *= 10.0;
                continue;
            };
            let xn: Vec<f64> = (0..nx).map(|d| x[d] + step[d]).collect();
            let rn = residuals(&xn);
            if cost(&rn) < cost(&r) {
                taken_step = Some((step, xn, rn));
                mu = (mu * 0.3).max(1e-9);
                break;
            }
            mu *= 10.0;
        }
        let improved = taken_step.is_some();
        if let Some((s, xn, rn)) = taken_step {
            if refresh > 1 {
                // Broyden: J += (Δr − J s) sᵀ / (sᵀ s)
                let mut jac = jac;
                let y = mbs::DMatrix::from_fn(m, 1, |i, _| rn[i] - r[i]);
                let u = (y - &jac * &s) / s.norm_squared();
                jac += u * s.transpose();
                jacobian = Some((jac, age + 1));
            }
            x = xn;
            r = rn;
        }
        costs.push(cost(&r));
        let k = costs.len() - 1;
        // no lower cost on an updated Jacobian: differences next (jacobian is None)
        if !improved && age == 0 {
            break;
        }
        if k >= window && costs[k] > (1.0 - tol) * costs[k - window] {
            break;
        }
    }
    (x, taken)
}

/// The Jacobian of `residuals` at `x` (where they are `r`) by forward differences of
/// `step`, its columns shared among the cores.
fn differences(
    nx: usize,
    residuals: &(dyn Fn(&[f64]) -> Vec<f64> + Sync),
    x: &[f64],
    r: &[f64],
    step: f64,
) -> mbs::DMatrix<f64> {
    let m = r.len();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let columns: Vec<Vec<Vec<f64>>> = std::thread::scope(|scope| {
        let chunks: Vec<_> = (0..threads)
            .map(|t| {
                scope.spawn(move || {
                    (t..nx)
                        .step_by(threads)
                        .map(|c| {
                            let mut xp = x.to_vec();
                            xp[c] += step;
                            let rp = residuals(&xp);
                            (0..m).map(|i| (rp[i] - r[i]) / step).collect::<Vec<f64>>()
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        chunks
            .into_iter()
            .map(|h| h.join().expect("a column's thread"))
            .collect()
    });
    // column c is the (c / threads)-th of thread c % threads
    mbs::DMatrix::from_fn(m, nx, |i, c| columns[c % threads][c / threads][i])
}

/// Mode 1's settings, shared by the gait program and its test, chosen on the normal cycle
/// of 1.1 s made symmetric (`human_gait --kp …, --dissipation …, --period …`: every figure
/// stays in the normal ranges for a tracking stiffness of 1e4 or 1e5 N·m/rad, a dissipation
/// of 10 or 20 s/m and a cycle of 1.0 s; the first peak reaches 1.32 body weights at 5 s/m
/// and 1.84 at the model's 1 s/m, the second 1.31 for a cycle of 1.2 s):
/// - the published cycle fitted with 5 harmonics (8 follow the table's samples closer; the
///   figures were worked out with 5);
pub const FIT_HARMONICS: usize = 5;
/// - the joints tracked with 3·10⁴ N·m/rad (and a hundredth of it in N·m·s/rad): at
///   3·10³ the legs lag the reference and the fore–aft force propels first, then brakes
///   (with that run's joint torques as feedforward, [`Tracking::feedforward_of`], 10³ gives
///   its forces within 0.05 body weights);
pub const GAIT_KP: f64 = 3e4;
/// - the feet's Hunt–Crossley dissipation 10 s/m (the model's 1 s/m, a hard sole, lets the
///   heel strike peak at 1.8 body weights: the tracked legs have no muscles' give);
pub const GAIT_DISSIPATION: f64 = 10.0;
/// - the pelvis' orientation held by residual torques of 3·10⁴ N·m/rad (and a tenth of it
///   in N·m·s/rad).
pub const GAIT_PELVIS_KP: f64 = 3e4;

/// What [`GaitReference::grounded`] asks of a cycle.
#[derive(Clone, Debug)]
pub struct Grounding {
    /// the cycle fractions [start, end) of the two double supports, the right foot in front
    /// in the first
    pub double: [[f64; 2]; 2],
    /// the swinging foot's clearance at mid-swing (m)
    pub clearance: f64,
    /// the bounds on the centre of mass' acceleration along the world's axes: fore–aft,
    /// vertical, lateral (in g)
    pub max_acceleration: [f64; 3],
    /// harmonics of the corrections
    pub harmonics: usize,
    /// instants of the cycle
    pub samples: usize,
    /// Levenberg–Marquardt iterations at most
    pub iterations: usize,
    /// the weight of the corrections' coefficients (per radian) against the residuals
    /// (centimetres of level or clearance, tenths of g beyond the bound)
    pub penalty: f64,
    /// the weights of what the cycle asks of the ground ([`Grounded::pressure_beyond`],
    /// [`Grounded::free_moment`]): of the distance by which the centre of pressure its motion
    /// needs lies beyond the standing feet, times the vertical force in body weights (per
    /// metre), and of the free moment (per body weight × metre). Zero (the default) leaves
    /// them out. Asked of a cycle already grounded (`grounded` again on its reference), so
    /// that the pass starts near the answer: asked of the fitted cycle, whose centre of
    /// pressure lies metres off, the corrections land in different places for weights a
    /// factor of three apart
    pub pressure: [f64; 2],
}

impl Default for Grounding {
    /// The normal cycle's events (right heel strike at 0, left toe-off at 13 %, left heel
    /// strike at 50 %, right toe-off at 63 %), 2 cm of clearance, ± 0.25 g fore–aft, ± 0.2 g
    /// vertically (the dynamics add a few hundredths to the peaks) and ± 0.1 g laterally,
    /// five harmonics, 100 instants, 800 iterations at most, a penalty of 3, no weight on
    /// the centre of pressure.
    fn default() -> Self {
        Grounding {
            double: [[0.0, 0.13], [0.5, 0.63]],
            clearance: 0.02,
            max_acceleration: [0.25, 0.2, 0.1],
            harmonics: 5,
            samples: 100,
            iterations: 800,
            penalty: 3.0,
            pressure: [0.0; 2],
        }
    }
}

/// A grounded reference and how well it meets [`Grounding`]'s asks.
#[derive(Clone, Debug)]
pub struct Grounded {
    pub reference: GaitReference,
    /// the largest height difference of the feet in double support (m)
    pub level: f64,
    /// the least margin of the swinging foot over the clearance asked (m; negative: short)
    pub clearance: f64,
    /// the least and largest acceleration of the centre of mass along each world axis (g)
    pub acceleration: [[f64; 2]; 3],
    /// the largest difference of the feet's horizontal velocities in double support (m/s)
    pub slip: f64,
    /// the walking speed: the mean backward speed of the standing contact relative to the
    /// pelvis' translation (m/s); the pass keeps the uncorrected reference's
    pub speed: f64,
    /// the largest correction of an angle (rad)
    pub largest_change: f64,
    pub iterations: usize,
    /// what the cycle asks of the ground, which the pass does not correct (the residual
    /// torques on the pelvis supply what the feet cannot): the largest distance (m) by
    /// which the centre of pressure the motion needs (its angular momentum's rate about the
    /// centre of mass and the centre's acceleration) lies beyond the standing feet's
    /// support, fore–aft and lateral (along and across the line between the feet in double
    /// support)
    pub pressure_beyond: [f64; 2],
    /// and the largest free moment about the vertical it needs there (N·m)
    pub free_moment: f64,
}

const G: f64 = 9.80665;

/// The centre of pressure (x, z) on the ground y = `ground` of a force `force` whose moment
/// about the point `com` is `moment` (world axes, y up), and the free moment about the
/// vertical it then needs there: the point c on the ground where (c − com) × F has the
/// moment's horizontal components, and what is left of its vertical one. For a body's
/// motion, F = m (a_G + g ŷ) and the moment about the centre of mass the rate of the
/// angular momentum about it. NaN when the force has no vertical component.
pub fn pressure_point(
    force: [f64; 3],
    moment: [f64; 3],
    com: [f64; 3],
    ground: f64,
) -> ([f64; 2], f64) {
    let (f, dy) = (force, ground - com[1]);
    // (d × F)_x = dy Fz − dz Fy = Mx, (d × F)_z = dx Fy − dy Fx = Mz
    let dz = (dy * f[2] - moment[0]) / f[1];
    let dx = (moment[2] + dy * f[0]) / f[1];
    let free = moment[1] - (dz * f[0] - dx * f[2]);
    ([com[0] + dx, com[2] + dz], free)
}

/// The model's mass (the translation block of its mass matrix).
pub fn total_mass(model: &Human) -> f64 {
    let n = Human::NQ;
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    let mut m = vec![0.0; n * n];
    model.mass_matrix(0.0, &q, &mut m);
    m[0]
}

/// The centre of mass and the angular momentum about it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Centroid {
    /// the centre of mass (world, m)
    pub position: [f64; 3],
    /// the linear momentum (world, kg·m/s)
    pub momentum: [f64; 3],
    /// the angular momentum about the centre of mass (world axes, kg·m²/s)
    pub angular_momentum: [f64; 3],
}

impl Centroid {
    /// At (t, q, q̇), from `model`'s mass matrix there and its pelvis' chart C (q, q̇ read
    /// in it, as the simulation left them: [`mbs::charts::use_charts_of`]). The pelvis'
    /// angles turn about the world axes a₁ = C z, a₂ = C Rz(a) y, a₃ = C Rz(a) Ry(b) x at the
    /// pelvis' origin O, so the translation rows of their columns of M are m (aⱼ × r), r the
    /// centre of mass from O, and their generalised momenta are aⱼ · H_O. The pelvis'
    /// translation rows give the momentum; H_G = H_O − r × p. `None` where the axes are
    /// dependent (cos b = 0, the chart's singularity, which the simulation re-centres away
    /// from).
    pub fn of(model: &Human, t: f64, q: &[f64], qd: &[f64]) -> Option<Centroid> {
        let nq = Human::NQ;
        let mut m = vec![0.0; nq * nq];
        model.mass_matrix(t, q, &mut m);
        Centroid::from_mass_matrix(model, q, qd, &m)
    }

    /// As [`Centroid::of`], `m` the mass matrix at q (row-major).
    fn from_mass_matrix(model: &Human, q: &[f64], qd: &[f64], m: &[f64]) -> Option<Centroid> {
        let nq = Human::NQ;
        let row = |r: usize| (0..nq).map(|j| m[r * nq + j] * qd[j]).sum::<f64>();
        let (axes, rel) = pelvis_axes_and_centre(model, q, m);
        let cross = |u: [f64; 3], v: [f64; 3]| {
            [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ]
        };
        let a = mbs::DMatrix::from_fn(3, 3, |i, j| axes[i][j]);
        let h_o = a.lu().solve(&mbs::DMatrix::from_column_slice(
            3,
            1,
            &[row(3), row(4), row(5)],
        ))?;
        let p = [row(0), row(1), row(2)];
        let rp = cross(rel, p);
        Some(Centroid {
            position: std::array::from_fn(|k| q[k] + rel[k]),
            momentum: p,
            angular_momentum: std::array::from_fn(|k| h_o[k] - rp[k]),
        })
    }
}

/// The world axes the pelvis' angles turn about, a₁ = C z, a₂ = C Rz(a) y,
/// a₃ = C Rz(a) Ry(b) x (C the model's chart of the pelvis), and the centre of mass from the
/// pelvis' origin, r, from the translation rows of the angles' columns of `m` (the mass
/// matrix at q, row-major), which are m (aⱼ × r).
fn pelvis_axes_and_centre(model: &Human, q: &[f64], m: &[f64]) -> ([[f64; 3]; 3], [f64; 3]) {
    let nq = Human::NQ;
    let mass = m[0];
    let column = |j: usize| [0, 1, 2].map(|r| m[r * nq + j] / mass);
    let c = model.chart(0);
    let turn =
        |v: [f64; 3]| -> [f64; 3] { std::array::from_fn(|i| (0..3).map(|k| c[i][k] * v[k]).sum()) };
    let (sa, ca) = q[3].sin_cos();
    let (sb, cb) = q[4].sin_cos();
    let axes = [
        turn([0.0, 0.0, 1.0]),
        turn([-sa, ca, 0.0]),
        turn([ca * cb, sa * cb, -sb]),
    ];
    let cross = |u: [f64; 3], v: [f64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let dot = |u: [f64; 3], v: [f64; 3]| (0..3).map(|i| u[i] * v[i]).sum::<f64>();
    // r from a₁ × r and a₂ × r (a₁ ⊥ a₂): its part across a₁, (a₁ × r) × a₁, and its
    // part along a₁, which lies across a₂
    let across = cross(column(3), axes[0]);
    let along = dot(cross(column(4), axes[1]), axes[0]);
    (
        axes,
        std::array::from_fn(|i| across[i] + along * axes[0][i]),
    )
}

/// The centre of mass (world) and the linear momentum at (q, q̇), `m` the mass matrix at q
/// (row-major), the pelvis' angles read in `model`'s chart; no allocation.
pub fn mass_centre(model: &Human, q: &[f64], qd: &[f64], m: &[f64]) -> ([f64; 3], [f64; 3]) {
    let nq = Human::NQ;
    let row = |r: usize| (0..nq).map(|j| m[r * nq + j] * qd[j]).sum::<f64>();
    let (_, rel) = pelvis_axes_and_centre(model, q, m);
    (
        std::array::from_fn(|k| q[k] + rel[k]),
        [row(0), row(1), row(2)],
    )
}

/// The whole-body angular momentum about the centre of mass over the last whole cycle of
/// `tr` (a run of `model`, its first `Human::NQ` coordinates; [`last_cycle_start`]),
/// normalised as Herr & Popovic (2008, "Angular momentum in human walking") do: by the mass,
/// the centre of mass' mean height over the ground and the walking speed (its mean
/// fore–aft speed over the cycle). Per world axis (fore–aft x, vertical y, lateral z): the
/// least and the largest value, and (M, V, H). `None` if the run has fewer than two
/// samples in that cycle, walks forward (x) at less than 0.1 m/s over it (the normalisation
/// needs a walking speed), or reaches the pelvis' angles' singularity.
pub fn normalised_angular_momentum(
    model: &Human,
    tr: &mbs::Trajectory,
    period: f64,
) -> Option<([[f64; 2]; 3], [f64; 3])> {
    let n = Human::NQ;
    let mass = total_mass(model);
    let start = last_cycle_start(tr, period);
    let mut model = model.clone();
    let mut samples = Vec::new();
    for s in (0..tr.len()).filter(|s| tr.t[*s] >= start - 1e-9) {
        let (q, qd) = (&tr.q(s)[..n], &tr.qd(s)[..n]);
        mbs::charts::use_charts_of(&mut model, tr, s);
        samples.push((tr.t[s], Centroid::of(&model, tr.t[s], q, qd)?));
    }
    let (first, last) = (samples.first()?, samples.last()?);
    let time = last.0 - first.0;
    if samples.len() < 2 || time <= 0.0 {
        return None;
    }
    let speed = (last.1.position[0] - first.1.position[0]) / time;
    if speed < 0.1 {
        return None;
    }
    let height = samples.iter().map(|(_, c)| c.position[1]).sum::<f64>() / samples.len() as f64;
    let scale = mass * speed * height;
    let range = |k: usize| {
        samples
            .iter()
            .map(|(_, c)| c.angular_momentum[k] / scale)
            .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], v| {
                [lo.min(v), hi.max(v)]
            })
    };
    Some(([range(0), range(1), range(2)], [mass, speed, height]))
}

/// The least-squares problem of [`GaitReference::grounded`].
struct Pass<'a> {
    model: &'a Human,
    /// the uncorrected reference's (q, q̇) at each instant
    states: Vec<(Vec<f64>, Vec<f64>)>,
    period: f64,
    /// (index in the reference's joints, coordinate) per leg and joint
    joints: [[(usize, usize); 5]; 2],
    how: &'a Grounding,
    feet: Feet,
    weight: f64,
    /// the uncorrected reference's walking speed (m/s), which the corrections keep
    speed: f64,
}

impl Pass<'_> {
    /// Correction of joint `j` of leg `leg` at cycle fraction `phase`: angle and rate.
    fn correction(&self, x: &[f64], j: usize, phase: f64, leg: usize) -> (f64, f64) {
        let h = self.how.harmonics;
        let c = &x[j * (2 * h + 1)..(j + 1) * (2 * h + 1)];
        let phase = if leg == 0 { phase } else { phase - 0.5 };
        let (mut v, mut rate) = (c[0], 0.0);
        for m in 1..=h {
            let w = std::f64::consts::TAU * m as f64;
            let (s, co) = (w * phase).sin_cos();
            v += c[m] * co + c[h + m] * s;
            rate += w / self.period * (c[h + m] * co - c[m] * s);
        }
        (v, rate)
    }

    /// The corrected reference at each instant of the cycle; `with_momentum`, each sample's
    /// angular momentum and centre of mass' z too (what the centre of pressure needs; NaN
    /// without).
    fn samples(&self, x: &[f64], kin: &mut Kinematics, with_momentum: bool) -> Vec<Sample> {
        let n = self.how.samples;
        let nq = Human::NQ;
        let (mut q, mut qd, mut m) = (vec![0.0; nq], vec![0.0; nq], vec![0.0; nq * nq]);
        (0..n)
            .map(|s| {
                let phase = s as f64 / n as f64;
                let (q0, qd0) = &self.states[s];
                q.copy_from_slice(q0);
                qd.copy_from_slice(qd0);
                for (leg, row) in self.joints.iter().enumerate() {
                    for (j, (_, i)) in row.iter().enumerate() {
                        let (v, rate) = self.correction(x, j, phase, leg);
                        q[*i] += v;
                        qd[*i] += rate;
                    }
                }
                self.model.motion(0.0, &q, &qd, kin);
                let sp = self.feet.support_points(kin);
                // each foot's lowest point and its contact's velocity, smoothed over the
                // ellipsoids (a soft minimum of their heights and the velocities weighted
                // alike) so that the residuals change smoothly as the foot rolls from one
                // ellipsoid to the next
                let lowest = |k: usize| {
                    let hard = sp[k].iter().map(|p| p.0[1]).fold(f64::INFINITY, f64::min);
                    let w = sp[k].map(|p| (-(p.0[1] - hard) / SOFT).exp());
                    let sum: f64 = w.iter().sum();
                    let low = hard - SOFT * sum.ln();
                    let v = [0, 2]
                        .map(|j| sp[k].iter().zip(&w).map(|(p, w)| w * p.1[j]).sum::<f64>() / sum);
                    let x = [0, 2]
                        .map(|j| sp[k].iter().zip(&w).map(|(p, w)| w * p.0[j]).sum::<f64>() / sum);
                    (low, v, x)
                };
                let (r, l) = (lowest(0), lowest(1));
                let (low, contact, at) = ([r.0, l.0], [r.1, l.1], [r.2, l.2]);
                // the centre of mass' height from the potential, lifted clear of the ground;
                // its velocity from the momentum (the pelvis' translation at rest)
                q[1] += 2.0;
                let com = self.model.energy(0.0, &q, &qd).potential / self.weight - 2.0;
                self.model.mass_matrix(0.0, &q, &mut m);
                let mass = self.weight / G;
                let momentum = |r: usize| (0..nq).map(|j| m[r * nq + j] * qd[j]).sum::<f64>();
                // the centre of mass' x from the mass matrix' column of the pelvis' first
                // angle (a rotation about the world's z: Σ mᵢ ẑ × (x_Gᵢ − pelvis))
                let com_x = q[0] + m[nq + 3] / mass;
                // the angular momentum about the centre of mass and the centre's z (NaN at
                // the pelvis' angles' singularity)
                let centroid = with_momentum
                    .then(|| Centroid::from_mass_matrix(self.model, &q, &qd, &m))
                    .flatten();
                Sample {
                    low,
                    height: com - low[0].min(low[1]),
                    contact,
                    contact_x: [at[0][0], at[1][0]],
                    contact_z: [at[0][1], at[1][1]],
                    com_x,
                    com_z: centroid.map_or(f64::NAN, |c| c.position[2]),
                    angular_momentum: centroid.map_or([f64::NAN; 3], |c| c.angular_momentum),
                    support: sp.map(|f| f.map(|p| p.0)),
                    com_velocity: [momentum(0) / mass, momentum(2) / mass],
                }
            })
            .collect()
    }

    /// The standing feet (right, left) at instant `s` of `n`.
    fn stands(&self, s: usize, n: usize) -> [bool; 2] {
        match self.phase(s as f64 / n as f64) {
            Some((true, _)) => [true, false],
            Some((false, _)) => [false, true],
            None => [true, true],
        }
    }

    /// Whether `phase` is in double support; else whether the right foot stands, and the
    /// fraction of the swing.
    fn phase(&self, phase: f64) -> Option<(bool, f64)> {
        let d = self.how.double;
        if d.iter().any(|[a, b]| phase >= *a && phase < *b) {
            return None;
        }
        let right = phase >= d[0][1] && phase < d[1][0];
        let (a, b) = if right {
            (d[0][1], d[1][0])
        } else {
            (d[1][1], 1.0 + d[0][0])
        };
        Some((right, (phase - a) / (b - a)))
    }

    /// (gap asked, gap) of the swinging foot at an instant in single support.
    fn gap(&self, right: bool, u: f64, low: &[f64; 2]) -> (f64, f64) {
        let asked = self.how.clearance * (std::f64::consts::PI * u).sin();
        (
            asked,
            if right {
                low[1] - low[0]
            } else {
                low[0] - low[1]
            },
        )
    }

    /// The standing contact's horizontal velocity (x, z) at instant `s` of `samples` (the
    /// mean of the two feet's in double support).
    fn standing(&self, samples: &[Sample], s: usize) -> [f64; 2] {
        let c = &samples[s].contact;
        match self.phase(s as f64 / samples.len() as f64) {
            None => [0, 1].map(|k| 0.5 * (c[0][k] + c[1][k])),
            Some((true, _)) => c[0],
            Some((false, _)) => c[1],
        }
    }

    /// The walking speed: the mean backward speed of the standing contact.
    fn speed(&self, samples: &[Sample]) -> f64 {
        -(0..samples.len())
            .map(|s| self.standing(samples, s)[0])
            .sum::<f64>()
            / samples.len() as f64
    }

    /// The centre of mass' acceleration along the world's axes at each instant (g): the
    /// vertical from its height, the horizontal from its velocity relative to the ground
    /// (its velocity relative to the pelvis' translation less the standing contact's).
    fn accelerations(&self, samples: &[Sample]) -> Vec<[f64; 3]> {
        let n = samples.len();
        let dt = self.period / n as f64;
        let ground = |s: usize| {
            let stand = self.standing(samples, s);
            [0, 1].map(|k| samples[s].com_velocity[k] - stand[k])
        };
        (0..n)
            .map(|s| {
                let (p, q) = ((s + n - 1) % n, (s + 1) % n);
                let (vp, vq) = (ground(p), ground(q));
                let h = |s: usize| samples[s].height;
                [
                    (vq[0] - vp[0]) / (2.0 * dt) / G,
                    (h(q) - 2.0 * h(s) + h(p)) / (dt * dt) / G,
                    (vq[1] - vp[1]) / (2.0 * dt) / G,
                ]
            })
            .collect()
    }

    fn residuals(&self, x: &[f64], kin: &mut Kinematics) -> Vec<f64> {
        let [wp, wf] = self.how.pressure;
        let samples = self.samples(x, kin, wp != 0.0 || wf != 0.0);
        let acc = self.accelerations(&samples);
        let n = samples.len();
        let mut r = Vec::with_capacity(7 * n + 1 + x.len());
        for (s, sample) in samples.iter().enumerate() {
            // centimetres, tenths of a metre per second, and tenths of g beyond the bounds
            let low = &sample.low;
            match self.phase(s as f64 / n as f64) {
                None => {
                    r.push(100.0 * (low[0] - low[1]));
                    let c = &sample.contact;
                    r.extend([0, 1].map(|k| 10.0 * (c[0][k] - c[1][k])));
                }
                Some((right, u)) => {
                    let (asked, gap) = self.gap(right, u, low);
                    r.push(100.0 * (asked - gap).max(0.0));
                    r.extend([0.0, 0.0]);
                }
            }
            // in single support the ground's force points at the centre of mass from the
            // standing foot's contact (no moment about the centre of mass): fore–aft force
            // over vertical force = (x_G − x_c) / height
            let pivot = match self.phase(s as f64 / n as f64) {
                Some((right, _)) => {
                    let c = sample.contact_x[if right { 0 } else { 1 }];
                    let lean = (sample.com_x - c) / sample.height;
                    acc[s][0] - (1.0 + acc[s][1]) * lean
                }
                None => 0.0,
            };
            r.push(10.0 * pivot);
            // the centre of pressure the motion needs within the standing feet, and a small
            // free moment ([`Grounding::pressure`])
            if wp != 0.0 || wf != 0.0 {
                let (cop, free) = self.centre_of_pressure(&samples, &acc, s);
                for v in sample.beyond(cop, self.stands(s, n)) {
                    r.push(wp * (1.0 + acc[s][1]) * v);
                }
                r.push(wf * free / self.weight);
            }
            for (a, bound) in acc[s].iter().zip(self.how.max_acceleration) {
                r.push(10.0 * (a.abs() - bound).max(0.0));
            }
        }
        // the walking speed kept (tenths of a metre per second)
        r.push(10.0 * (self.speed(&samples) - self.speed));
        let per = 2 * self.how.harmonics + 1;
        for (c, v) in x.iter().enumerate() {
            let j = c / per;
            let w = self.how.penalty * if j == 1 || j == 2 { 2.0 } else { 1.0 };
            r.push(w * v);
        }
        r
    }

    /// The centre of pressure (x, z) the ground's force must have at instant `s` of
    /// `samples` (`acc` their accelerations, g) for the reference's motion, and the free
    /// moment about the vertical it needs there (N·m): the ground's force is m (a + g ŷ), and
    /// its moment about the centre of mass, from a point on the ground (the lower foot's
    /// height), must be the angular momentum's rate (central differences over the cycle).
    fn centre_of_pressure(
        &self,
        samples: &[Sample],
        acc: &[[f64; 3]],
        s: usize,
    ) -> ([f64; 2], f64) {
        let n = samples.len();
        let dt = self.period / n as f64;
        let (p, q) = ((s + n - 1) % n, (s + 1) % n);
        let hd: [f64; 3] = std::array::from_fn(|k| {
            (samples[q].angular_momentum[k] - samples[p].angular_momentum[k]) / (2.0 * dt)
        });
        let f = [0, 1, 2].map(|k| self.weight * (acc[s][k] + if k == 1 { 1.0 } else { 0.0 }));
        let sample = &samples[s];
        pressure_point(f, hd, [sample.com_x, sample.height, sample.com_z], 0.0)
    }

    /// The largest distances by which the centre of pressure the motion needs lies beyond
    /// the standing feet's support over the cycle ([`Sample::beyond`]: fore–aft and lateral
    /// in single support, along and across the line between the feet in double support,
    /// the larger of each pair), and the largest free moment it needs (N·m); NaN where the
    /// pelvis' angles are singular.
    fn pressure(&self, samples: &[Sample]) -> ([f64; 2], f64) {
        let acc = self.accelerations(samples);
        let n = samples.len();
        let (mut beyond, mut free) = ([0.0f64; 2], 0.0f64);
        for s in 0..n {
            let (cop, moment) = self.centre_of_pressure(samples, &acc, s);
            let stands = self.stands(s, n);
            if cop.iter().chain([&moment]).any(|v| v.is_nan()) {
                return ([f64::NAN; 2], f64::NAN);
            }
            let b = samples[s].beyond(cop, stands);
            beyond = [beyond[0].max(b[0]).max(b[1]), beyond[1].max(b[2]).max(b[3])];
            free = free.max(moment.abs());
        }
        (beyond, free)
    }

    /// (largest level difference, least clearance margin, [least, largest] acceleration per
    /// axis, largest slip in double support).
    fn measure(&self, samples: &[Sample]) -> (f64, f64, [[f64; 2]; 3], f64) {
        let n = samples.len();
        let (mut level, mut margin, mut slip) = (0.0f64, f64::INFINITY, 0.0f64);
        for (s, sample) in samples.iter().enumerate() {
            let low = &sample.low;
            match self.phase(s as f64 / n as f64) {
                None => {
                    level = level.max((low[0] - low[1]).abs());
                    let c = &sample.contact;
                    slip = slip.max((c[0][0] - c[1][0]).hypot(c[0][1] - c[1][1]));
                }
                Some((right, u)) => {
                    let (asked, gap) = self.gap(right, u, low);
                    margin = margin.min(gap - asked);
                }
            }
        }
        let acc = self.accelerations(samples);
        let range = |k: usize| {
            acc.iter()
                .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], a| {
                    [lo.min(a[k]), hi.max(a[k])]
                })
        };
        (level, margin, [range(0), range(1), range(2)], slip)
    }
}

/// The length over which [`Pass`] blends a foot's ellipsoids into its lowest point (m).
const SOFT: f64 = 5e-4;

/// The corrected reference at one instant, as [`Pass`] reads it.
struct Sample {
    /// the lowest point's height of each foot (m)
    low: [f64; 2],
    /// the centre of mass' height above the lower foot (m)
    height: f64,
    /// the horizontal velocity (x, z) of each foot's lowest material point, relative to the
    /// pelvis' translation (m/s)
    contact: [[f64; 2]; 2],
    /// the centre of mass' horizontal velocity (x, z) relative to the pelvis' translation
    com_velocity: [f64; 2],
    /// each foot's contact (its lowest points blended) and the centre of mass along x and
    /// z (m)
    contact_x: [f64; 2],
    contact_z: [f64; 2],
    com_x: f64,
    com_z: f64,
    /// the angular momentum about the centre of mass (world axes, kg·m²/s)
    angular_momentum: [f64; 3],
    /// each foot's ellipsoids' support points (world, m)
    support: [[[f64; 3]; 6]; 2],
}

impl Sample {
    /// How far the point `c` (x, z) lies beyond the support of the standing feet
    /// (`stands`) along four directions: ±x and ±z in single support, and in
    /// double support along and across the line from one foot's contact to the other's.
    /// The support's extent along a direction is a soft maximum of the feet's ellipsoids'
    /// support points along it, each weighted by how close it is to its foot's lowest (over
    /// 1 mm), so that it changes smoothly as a foot rolls.
    fn beyond(&self, c: [f64; 2], stands: [bool; 2]) -> [f64; 4] {
        let (t, n) = if stands == [true, true] {
            let d = [
                self.contact_x[0] - self.contact_x[1],
                self.contact_z[0] - self.contact_z[1],
            ];
            let l = d[0].hypot(d[1]).max(1e-9);
            ([d[0] / l, d[1] / l], [-d[1] / l, d[0] / l])
        } else {
            ([1.0, 0.0], [0.0, 1.0])
        };
        let dirs = [t, [-t[0], -t[1]], n, [-n[0], -n[1]]];
        dirs.map(|u| {
            let along = |p: &[f64; 3]| p[0] * u[0] + p[2] * u[1];
            let top = self
                .support
                .iter()
                .flatten()
                .map(along)
                .fold(f64::NEG_INFINITY, f64::max);
            let (mut num, mut den) = (0.0, 0.0);
            for (k, points) in self.support.iter().enumerate() {
                if !stands[k] {
                    continue;
                }
                let low = points.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
                for p in points {
                    let along = along(p);
                    let w = (-(p[1] - low) / 1e-3 + (along - top) / 5e-3).exp();
                    num += w * along;
                    den += w;
                }
            }
            let extent = num / den;
            (c[0] * u[0] + c[1] * u[1] - extent).max(0.0)
        })
    }
}

fn rot(axis: usize, a: f64) -> [[f64; 3]; 3] {
    let (s, c) = a.sin_cos();
    let mut r = [[0.0; 3]; 3];
    let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
    r[axis][axis] = 1.0;
    r[i][i] = c;
    r[j][j] = c;
    r[i][j] = -s;
    r[j][i] = s;
    r
}

fn mul(x: &[[f64; 3]; 3], y: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| x[i][k] * y[k][j]).sum()))
}

/// Stiff tracking of a [`GaitReference`]: a torque kp (q_ref − q) + kd (q̇_ref − q̇) on each
/// joint coordinate (an action–reaction pair between the bodies the joint connects), the
/// pelvis left free. The torques are the joint moments that make the model follow the cycle.
#[derive(Clone, Debug)]
pub struct Tracking {
    pub reference: GaitReference,
    /// stiffness (N·m/rad) and damping (N·m·s/rad)
    pub kp: f64,
    pub kd: f64,
    /// stiffness and damping of the toes' joints, which the gait table does not give: a
    /// passive spring about zero (N·m/rad, N·m·s/rad)
    pub toes_kp: f64,
    pub toes_kd: f64,
    /// the toes' coordinates
    toes: [usize; 2],
    /// residual torques on the pelvis' orientation (RRA's residual moments): stiffness
    /// (N·m/rad) and damping (N·m·s/rad) toward the reference's orientation; zero (the
    /// default) leaves the pelvis free
    pub pelvis_kp: f64,
    pub pelvis_kd: f64,
    /// the residual torques' share about each world axis (fore–aft, vertical, lateral): 1
    /// each by default, 0 leaves the pelvis free to turn about that axis
    pub pelvis_axes: [f64; 3],
    pelvis: usize,
    /// a balance controller ([`Balance`]): its ankle strategy turns the standing feet's
    /// references here, its foot placement needs [`Balanced`]; none by default
    pub balance: Option<Balance>,
    /// feedforward torques over the cycle, per tracked joint (in the order of the
    /// reference's joints), added to the stiffness' and damping's: none (empty) by default;
    /// [`Tracking::feedforward_of`] takes them from a run
    pub feedforward: Vec<Fourier>,
    pub guard: Guard,
}

impl Tracking {
    /// Every joint held on `reference` with stiffness `kp` and damping `kd` (the toes' too),
    /// the pelvis free, the [`Guard`] on.
    pub fn new(
        reference: GaitReference,
        info: &mbs::ModelInfo,
        kp: f64,
        kd: f64,
    ) -> Result<Tracking, String> {
        Ok(Tracking {
            reference,
            kp,
            kd,
            toes_kp: kp,
            toes_kd: kd,
            toes: [dof_index(info, "mtp[0]")?, dof_index(info, "mtp[1]")?],
            pelvis_kp: 0.0,
            pelvis_kd: 0.0,
            pelvis_axes: [1.0; 3],
            pelvis: info
                .frame_index("pelvis_o")
                .ok_or("the model has no frame `pelvis_o`")?,
            balance: None,
            feedforward: Vec::new(),
            guard: Guard::new(info)?,
        })
    }

    /// The tracking torque on each joint coordinate at (t, q, qd): (coordinate, torque).
    pub fn torques<'a>(
        &'a self,
        t: f64,
        q: &'a [f64],
        qd: &'a [f64],
    ) -> impl Iterator<Item = (usize, f64)> + 'a {
        self.reference
            .joints
            .iter()
            .enumerate()
            .map(move |(k, (i, _))| {
                let [r, rd, _] = self.reference.joint(k, t);
                let (kp, kd) = if self.toes.contains(i) {
                    (self.toes_kp, self.toes_kd)
                } else {
                    (self.kp, self.kd)
                };
                let ff = self.feedforward.get(k).map_or(0.0, |f| f.value(t));
                (*i, ff + kp * (r - q[*i]) + kd * (rd - qd[*i]))
            })
    }

    /// The joints' torques of this tracking over the last whole cycle of `tr` (a run with
    /// it, sampled uniformly at a step that divides the period, as `Output::Every`),
    /// fitted with `harmonics` harmonics: the feedforward ([`Tracking::feedforward`]) of a
    /// tracking that follows that run with less stiffness. An error where `tr` does not
    /// cover a whole cycle so sampled, with more than 2 `harmonics` samples.
    pub fn feedforward_of(
        &self,
        tr: &mbs::Trajectory,
        harmonics: usize,
    ) -> Result<Vec<Fourier>, String> {
        let n = Human::NQ;
        let rows = last_cycle_rows(tr, self.reference.period, harmonics)?;
        let mut samples = vec![Vec::with_capacity(rows.len()); self.reference.joints.len()];
        for s in rows {
            for (k, (_, tau)) in self
                .torques(tr.t[s], &tr.q(s)[..n], &tr.qd(s)[..n])
                .enumerate()
            {
                samples[k].push(tau);
            }
        }
        Ok(samples
            .iter()
            .map(|y| Fourier::fit(y, harmonics, self.reference.period))
            .collect())
    }

    /// The rms over the last whole cycle of `tr` (a run with this tracking, sampled
    /// uniformly) of the tracking torques on the coordinates `names` (N·m): the joint
    /// moments, or with muscles the reserves' part of them.
    pub fn rms_over_last_cycle(
        &self,
        info: &mbs::ModelInfo,
        tr: &mbs::Trajectory,
        names: &[&str],
    ) -> Result<f64, String> {
        let n = Human::NQ;
        let joints = names
            .iter()
            .map(|name| dof_index(info, name))
            .collect::<Result<Vec<usize>, String>>()?;
        let start = last_cycle_start(tr, self.reference.period);
        let (mut sum, mut count) = (0.0, 0usize);
        for s in (0..tr.len()).filter(|s| tr.t[*s] >= start - 1e-9) {
            for (i, tau) in self.torques(tr.t[s], &tr.q(s)[..n], &tr.qd(s)[..n]) {
                if joints.contains(&i) {
                    sum += tau * tau;
                    count += 1;
                }
            }
        }
        Ok((sum / count.max(1) as f64).sqrt())
    }

    /// Stops holding the coordinates `names` (they are left to other efforts: muscles).
    pub fn release(&mut self, info: &mbs::ModelInfo, names: &[&str]) -> Result<(), String> {
        let drop = names
            .iter()
            .map(|n| dof_index(info, n))
            .collect::<Result<Vec<usize>, String>>()?;
        self.reference.joints.retain(|(i, _)| !drop.contains(i));
        Ok(())
    }
}

impl Tracking {
    /// The residual torque on the pelvis (world axes) at `t` and the kinematics `kin`:
    /// kp θ + kd (ω_ref − ω), θ the small rotation from the pelvis' orientation to the
    /// reference's, ½ vee(E − Eᵀ) with E = R_ref Rᵀ; ω_ref by central differences.
    pub fn pelvis_torque(&self, t: f64, kin: &Kinematics) -> [f64; 3] {
        if self.pelvis_kp == 0.0 && self.pelvis_kd == 0.0 {
            return [0.0; 3];
        }
        let (theta, dw) = self.pelvis_error(t, kin);
        std::array::from_fn(|i| {
            self.pelvis_axes[i] * (self.pelvis_kp * theta[i] + self.pelvis_kd * dw[i])
        })
    }

    /// The pelvis' orientation error at `t`: θ, the small rotation from its orientation to
    /// the reference's (½ vee(E − Eᵀ), E = R_ref Rᵀ), and ω_ref − ω (ω_ref by central
    /// differences), world axes.
    fn pelvis_error(&self, t: f64, kin: &Kinematics) -> ([f64; 3], [f64; 3]) {
        let k = &kin.frames[self.pelvis];
        let r = k.pose.rotation;
        let rr = self.reference.pelvis_rotation(t);
        let e: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..3).map(|m| rr[i][m] * r[j][m]).sum())
        });
        let theta = [
            0.5 * (e[2][1] - e[1][2]),
            0.5 * (e[0][2] - e[2][0]),
            0.5 * (e[1][0] - e[0][1]),
        ];
        let h = 1e-5;
        let (rp, rm) = (
            self.reference.pelvis_rotation(t + h),
            self.reference.pelvis_rotation(t - h),
        );
        let d: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..3).map(|m| rp[i][m] * rm[j][m]).sum())
        });
        let w_ref = [
            (d[2][1] - d[1][2]) / (4.0 * h),
            (d[0][2] - d[2][0]) / (4.0 * h),
            (d[1][0] - d[0][1]) / (4.0 * h),
        ];
        let w = k.angular_velocity;
        (theta, std::array::from_fn(|i| w_ref[i] - w[i]))
    }
}

/// The leg joints [`Tracking::reduced`] corrects: each leg's seven.
const REDUCED_JOINTS: [&str; 7] = [
    "hip_flexion",
    "hip_adduction",
    "hip_rotation",
    "knee",
    "ankle",
    "subtalar",
    "mtp",
];

/// What [`Tracking::reduced`] asks: a residual reduction with the model's own contacts.
#[derive(Clone, Debug)]
pub struct Reduction {
    /// harmonics of the corrections of each leg joint
    pub harmonics: usize,
    /// Levenberg–Marquardt iterations at most; one that takes the Jacobian by differences
    /// runs the held cycle once per unknown (7 joints × (2 `harmonics` + 1)), each runs it
    /// once or a few times more for its step
    pub iterations: usize,
    /// the weight of the corrections' coefficients (per radian) against the residual
    /// torques (per 10 N·m)
    pub penalty: f64,
    /// the weight of the change of each foot's vertical and fore–aft force from the
    /// uncorrected held cycle's (per body weight): the corrections keep its forces
    pub forces: f64,
    /// Radau5's rtol on the held runs
    pub rtol: f64,
    /// the held runs' output step, at which the residuals are read (s)
    pub sample: f64,
    /// the Jacobian by differences every `refresh` iterations, Broyden's updates between
    pub refresh: usize,
}

impl Default for Reduction {
    /// 5 harmonics, 8 iterations, the Jacobian by differences at each, penalty 10, forces
    /// 5, rtol 1e-6, samples every 10 ms: on the pressed cycle (`human_gait -- --pressure 30
    /// --free 10`) the residual torques fall from 112 to 7 N·m rms in 6 iterations and the
    /// pelvis walks a normal cycle wholly free, within 0.08 rad of its reference
    /// orientation. Broyden's updates between differences every 6 iterations (`refresh`)
    /// take a third of the time to 10 N·m in 12 iterations, with corrections a third as
    /// large, and the forces of the free cycle as normal, but the pelvis turns up to 0.21
    /// rad away from its reference.
    fn default() -> Self {
        Reduction {
            harmonics: 5,
            iterations: 8,
            penalty: 10.0,
            forces: 5.0,
            rtol: 1e-6,
            sample: 0.01,
            refresh: 1,
        }
    }
}

/// A cycle whose residual torques [`Tracking::reduced`] has lowered.
#[derive(Clone, Debug)]
pub struct Reduced {
    /// the corrected cycle
    pub reference: GaitReference,
    /// the residual torques' rms over the held run's second cycle, on the cycle given and
    /// on the corrected one (N·m)
    pub residual_rms: [f64; 2],
    /// the largest correction of an angle (rad)
    pub largest_change: f64,
    /// the largest correction of each leg joint (the right leg's name, rad)
    pub changes: Vec<(String, f64)>,
    pub iterations: usize,
    /// the held run on the corrected cycle (two cycles from [`cycle_start`])
    pub held: mbs::Trajectory,
    /// its time and state (q, q̇) at the start of its second cycle: where a run with the
    /// pelvis free starts on its own motion
    pub start: (f64, Vec<f64>, Vec<f64>),
}

/// The held run's second cycle, as [`Tracking::reduced`] reads it.
struct HeldCycle {
    tr: mbs::Trajectory,
    /// the residual torque at each output (world axes, N·m)
    torques: Vec<f64>,
    /// the feet's vertical and fore–aft forces at each output (body weights)
    forces: Vec<f64>,
}

impl Tracking {
    /// Residual reduction with the model's contacts: this tracking's cycle with its leg
    /// joints corrected (each leg's seven, periodic series of `how.harmonics`, the legs
    /// half a cycle apart) until the residual torques that hold the pelvis on its
    /// reference orientation nearly vanish, so that the feet's contacts carry the motion
    /// and the pelvis can be let free. OpenSim's residual reduction adjusts the kinematics
    /// against measured ground forces; here the forces are the ellipsoids' own, read from a
    /// run: Levenberg–Marquardt over the corrections, whose residuals are the residual
    /// torques over the second cycle of a run held by this tracking from [`cycle_start`]
    /// (its pelvis' orientation held, its translation free), the change of each foot's
    /// vertical and fore–aft force from that of the uncorrected cycle (weighted by
    /// `how.forces`) and the corrections' coefficients (weighted by `how.penalty`); the
    /// Jacobian by forward differences of those runs, shared among the cores. An error
    /// where this tracking does not hold the pelvis about every axis, where a joint it
    /// corrects is not tracked, or where the held run on the uncorrected cycle stops.
    pub fn reduced(&self, model: &Human, how: &Reduction) -> Result<Reduced, String> {
        if self.pelvis_kp <= 0.0 || self.pelvis_axes.iter().any(|a| *a <= 0.0) {
            return Err(format!(
                "the residual reduction lowers the torques that hold the pelvis: the tracking \
                 must hold it about every axis (pelvis_kp > 0, pelvis_axes all > 0; it has \
                 pelvis_kp = {}, pelvis_axes = {:?})",
                self.pelvis_kp, self.pelvis_axes
            ));
        }
        let info = model.info();
        let reference = &self.reference;
        let slots = REDUCED_JOINTS
            .iter()
            .map(|name| {
                let mut legs = [0; 2];
                for (leg, k) in legs.iter_mut().enumerate() {
                    let i = dof_index(info, &format!("{name}[{leg}]"))?;
                    *k = reference
                        .joints
                        .iter()
                        .position(|(c, _)| *c == i)
                        .ok_or_else(|| format!("`{name}[{leg}]` is not tracked"))?;
                }
                Ok(legs)
            })
            .collect::<Result<Vec<[usize; 2]>, String>>()?;
        let h = how.harmonics;
        let nx = slots.len() * (2 * h + 1);
        let before = self
            .held_cycle(model, reference, how)
            .map_err(|e| format!("the held cycle before the reduction stopped: {e}"))?;
        let (nt, nf) = (before.torques.len(), before.forces.len());
        let residuals = |x: &[f64]| -> Vec<f64> {
            let mut r = match self.held_cycle(model, &reference.corrected(&slots, x, h), how) {
                // the torques per 10 N·m
                Ok(c) => c
                    .torques
                    .iter()
                    .map(|t| 0.1 * t)
                    .chain(
                        c.forces
                            .iter()
                            .zip(&before.forces)
                            .map(|(f, f0)| how.forces * (f - f0)),
                    )
                    .collect(),
                // a run that stops: a step the search rejects
                Err(_) => vec![1e3; nt + nf],
            };
            r.resize(nt + nf, 1e3);
            r.extend(x.iter().map(|c| how.penalty * c));
            r
        };
        let (x, iterations) =
            levenberg_marquardt(nx, &residuals, how.iterations, 1e-4, 1e-2, how.refresh);
        let corrected = reference.corrected(&slots, &x, h);
        let after = self
            .held_cycle(model, &corrected, how)
            .map_err(|e| format!("the held cycle after the reduction stopped: {e}"))?;
        let rms = |t: &[f64]| (t.iter().map(|v| v * v).sum::<f64>() / (t.len() / 3) as f64).sqrt();
        let changes: Vec<(String, f64)> = REDUCED_JOINTS
            .iter()
            .zip(&slots)
            .map(|(name, [k, _])| {
                let change = (0..200)
                    .map(|s| s as f64 / 200.0 * reference.period)
                    .map(|t| (corrected.joint(*k, t)[0] - reference.joint(*k, t)[0]).abs())
                    .fold(0.0, f64::max);
                (format!("{name}[0]"), change)
            })
            .collect();
        let largest_change = changes.iter().map(|(_, c)| *c).fold(0.0, f64::max);
        let period = reference.period;
        let i = (0..after.tr.len())
            .find(|i| after.tr.t[*i] >= period - 1e-9)
            .ok_or("the held cycle has no output at its second cycle's start")?;
        let n = Human::NQ;
        let start = (
            after.tr.t[i],
            after.tr.q(i)[..n].to_vec(),
            after.tr.qd(i)[..n].to_vec(),
        );
        Ok(Reduced {
            reference: corrected,
            residual_rms: [rms(&before.torques), rms(&after.torques)],
            largest_change,
            changes,
            iterations,
            held: after.tr,
            start,
        })
    }

    /// Two cycles of `reference` held by this tracking from [`cycle_start`], Radau5 at
    /// `how.rtol`, and the residual torques and the feet's forces at the outputs of the
    /// second.
    fn held_cycle(
        &self,
        model: &Human,
        reference: &GaitReference,
        how: &Reduction,
    ) -> Result<HeldCycle, String> {
        let period = reference.period;
        let (q0, qd0) = cycle_start(model, reference);
        let tracking = Tracking {
            reference: reference.clone(),
            ..self.clone()
        };
        let options = mbs::Options {
            q0: Some(q0),
            qd0: Some(qd0),
            output: mbs::Output::Every { dt: how.sample },
            ..mbs::Options::adaptive(2.0 * period, how.rtol)
        };
        let (tr, _) = mbs::simulate(
            mbs::WithEfforts::new(model.clone(), tracking.clone()),
            mbs::Scheme::Radau5,
            options,
        )
        .map_err(|e| e.to_string())?;
        let n = Human::NQ;
        let weight = total_mass(model) * G;
        let mut kin = Kinematics::new::<Human>();
        let (mut torques, mut forces) = (Vec::new(), Vec::new());
        for i in (0..tr.len()).filter(|i| tr.t[*i] >= period - 1e-9) {
            let f = ground_forces(model, tr.t[i], &tr.q(i)[..n], &tr.qd(i)[..n], &mut kin);
            torques.extend(tracking.pelvis_torque(tr.t[i], &kin));
            forces.extend([f[0][1], f[1][1], f[0][0], f[1][0]].map(|v| v / weight));
        }
        Ok(HeldCycle {
            tr,
            torques,
            forces,
        })
    }
}

impl Efforts for Tracking {
    /// only the ankle strategy of a balance reads Jacobians (the feet's); the pelvis' torque
    /// and the guard's forces are transmitted without them
    fn reads_jacobians(&self) -> bool {
        self.balance.as_ref().is_some_and(|b| b.ankle[0] != 0.0)
    }

    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        self.guard.apply(e)?;
        let (q, qd) = (e.q, e.qd);
        for (i, tau) in self.torques(e.t, q, qd) {
            e.generalized_force(i, tau);
        }
        let torque = self.pelvis_torque(e.t, e.kin);
        if torque != [0.0; 3] {
            e.torque_on_frame(self.pelvis, torque);
        }
        if let Some(b) = &self.balance {
            for (joints, dq) in b.ankle_changes(self, e.t, e.kin) {
                for (j, d) in joints.iter().zip(dq) {
                    e.generalized_force(*j, self.kp * d);
                }
            }
        }
        Ok(())
    }
}

/// Points per cycle of [`Balance`]'s table.
const BALANCE_POINTS: usize = 400;

/// A balance controller for the tracked cycle with the pelvis free to pitch and roll. It
/// turns the joints' references in two ways:
///
/// - **ankle strategy** ([`Tracking::balance`]): the standing feet's ankle, subtalar and hip
///   rotation references turn so that, the foot held, they would turn the pelvis by
///   g (θ + τ (ω_ref − ω)) toward its reference orientation (θ its orientation error), each
///   foot by its nearness to the ground (fully within 2 mm, not from 10 mm up);
/// - **foot placement** ([`Balanced`], filtered): the swinging legs' hip flexion, adduction
///   and knee references turn so that the foot moves, level, by c_d e + c_v ė horizontally
///   (clamped to 0.1 m each way), as Hof's extrapolated centre of mass asks, e the centre of
///   mass relative to the standing feet's soles less the reference cycle's at the same
///   instant, each foot weighted by its nearness and stillness (none from 0.3 m/s).
#[derive(Clone, Debug)]
pub struct Balance {
    /// g and τ (s) of the ankle strategy
    pub ankle: [f64; 2],
    /// c_d (m/m) and c_v (s) of the foot placement
    pub placement: [f64; 2],
    /// over the cycle, per foot: the centre of mass' position and velocity relative to the
    /// foot's sole in the reference cycle (x and z of each)
    table: Vec<[[f64; 4]; 2]>,
    /// per leg: the calcaneus frame, the ankle, subtalar and hip rotation coordinates, the
    /// hip flexion, adduction and knee coordinates
    legs: [(usize, [usize; 3], [usize; 3]); 2],
    feet: Feet,
}

impl Balance {
    /// The controller for `reference` (its table of the centre of mass over the feet).
    pub fn new(
        model: &Human,
        reference: &GaitReference,
        ankle: [f64; 2],
        placement: [f64; 2],
    ) -> Result<Balance, String> {
        let info = model.info();
        let mut legs = [(0, [0; 3], [0; 3]); 2];
        for (k, leg) in legs.iter_mut().enumerate() {
            let dof = |n: &str| dof_index(info, &format!("{n}[{k}]"));
            let calcn = format!("calcn_o[{k}]");
            *leg = (
                info.frame_index(&calcn)
                    .ok_or(format!("the model has no frame `{calcn}`"))?,
                [dof("ankle")?, dof("subtalar")?, dof("hip_rotation")?],
                [dof("hip_flexion")?, dof("hip_adduction")?, dof("knee")?],
            );
        }
        let feet = Feet::of(info);
        let mut kin = Kinematics::new::<Human>();
        let mut m = vec![0.0; Human::NQ * Human::NQ];
        let mut table = Vec::with_capacity(BALANCE_POINTS);
        for i in 0..BALANCE_POINTS {
            let t = reference.period * i as f64 / BALANCE_POINTS as f64;
            let (q, qd) = reference_state(model, reference, t);
            model.motion(t, &q, &qd, &mut kin);
            model.mass_matrix(t, &q, &mut m);
            let (g, p) = mass_centre(model, &q, &qd, &m);
            let v = p.map(|p| p / m[0]);
            let soles = feet.support_points(&kin).map(sole);
            table.push(soles.map(|(x, w)| [g[0] - x[0], g[2] - x[2], v[0] - w[0], v[2] - w[2]]));
        }
        Ok(Balance {
            ankle,
            placement,
            table,
            legs,
            feet,
        })
    }

    /// The reference's relative position and velocity over foot `k` at `t` (linear between
    /// the table's points, periodic).
    fn reference(&self, period: f64, k: usize, t: f64) -> [f64; 4] {
        let n = self.table.len();
        let x = (t / period).rem_euclid(1.0) * n as f64;
        let i = (x.floor() as usize).min(n - 1);
        let f = x - i as f64;
        let (a, b) = (self.table[i][k], self.table[(i + 1) % n][k]);
        std::array::from_fn(|j| a[j] + f * (b[j] - a[j]))
    }

    /// Each foot's nearness to the ground from its ellipsoids' support `points`: 1 within
    /// 2 mm, 0 from 10 mm up.
    fn nearness(points: &[[([f64; 3], [f64; 3]); 6]; 2]) -> [f64; 2] {
        points.map(|foot| {
            let low = foot.iter().map(|(x, _)| x[1]).fold(f64::INFINITY, f64::min);
            ((0.01 - low) / 0.008).clamp(0.0, 1.0)
        })
    }

    /// The ankle strategy's changes of the standing legs' references at `t`, `kin`: per leg,
    /// the ankle, subtalar and hip rotation coordinates and their changes (rad).
    pub fn ankle_changes(
        &self,
        tracking: &Tracking,
        t: f64,
        kin: &Kinematics,
    ) -> [([usize; 3], [f64; 3]); 2] {
        let mut out = self.legs.map(|(_, j, _)| (j, [0.0; 3]));
        let [g, tau] = self.ankle;
        if g == 0.0 {
            return out;
        }
        let near = Balance::nearness(&self.feet.support_points(kin));
        let sum = (near[0] + near[1]).max(1.0);
        let (theta, dw) = tracking.pelvis_error(t, kin);
        let r: [f64; 3] = std::array::from_fn(|i| -g * (theta[i] + tau * dw[i]));
        for (k, (frame, joints, _)) in self.legs.iter().enumerate() {
            if near[k] == 0.0 {
                continue;
            }
            // the pelvis turns relative to the foot by −Σ a_j Δq_j, a_j the foot's angular
            // velocity per unit rate of joint j: solve A Δq = −r
            if let Some(dq) = solve3(columns(&kin.frames[*frame].jw, joints), r) {
                out[k].1 = dq.map(|d| d * near[k] / sum);
            }
        }
        out
    }

    /// The foot placement's changes of the swinging legs' hip flexion, adduction and knee
    /// references at `t`, `kin`, the centre of mass at `g` moving at `v` (world).
    pub fn placement_changes(
        &self,
        period: f64,
        t: f64,
        kin: &Kinematics,
        g: [f64; 3],
        v: [f64; 3],
    ) -> [[f64; 3]; 2] {
        let mut out = [[0.0; 3]; 2];
        let [cd, cv] = self.placement;
        let points = self.feet.support_points(kin);
        let near = Balance::nearness(&points);
        let soles = points.map(sole);
        // the standing feet: near the ground and still (a foot swinging past it does not
        // count)
        let stand: [f64; 2] = std::array::from_fn(|k| {
            let w = soles[k].1;
            near[k] * (1.0 - w[0].hypot(w[2]) / 0.3).clamp(0.0, 1.0)
        });
        let total = stand[0] + stand[1];
        if total == 0.0 {
            return out;
        }
        let mut e = [0.0; 2];
        for k in 0..2 {
            let (x, w) = soles[k];
            let r = self.reference(period, k, t);
            for (a, j) in [0, 2].into_iter().enumerate() {
                let dx = g[j] - x[j] - r[a];
                let dv = v[j] - w[j] - r[2 + a];
                e[a] += stand[k] / total * (cd * dx + cv * dv);
            }
        }
        let e = e.map(|x| x.clamp(-0.1, 0.1));
        for (k, (frame, _, joints)) in self.legs.iter().enumerate() {
            let swing = 1.0 - near[k];
            if swing == 0.0 {
                continue;
            }
            // the foot moves by J Δq (hip flexion, adduction and knee columns), level
            let a = columns(&kin.frames[*frame].jv, joints);
            if let Some(dq) = solve3(a, [e[0], 0.0, e[1]]) {
                out[k] = dq.map(|d| swing * d);
            }
        }
        out
    }
}

/// [`Tracking`] (with its [`Balance`]'s ankle strategy, if any) and the balance's foot
/// placement, its changes of the references filtered: six extra states x, the changes of the
/// legs' hip flexion, adduction and knee references, ẋ = (target − x)/T. Unfiltered, the
/// placement and the stiff tracking close a loop faster than the body moves (the swinging
/// leg's reaction moves the centre of mass over the feet within milliseconds).
#[derive(Clone, Debug)]
pub struct Balanced {
    pub tracking: Tracking,
    /// T (s), > 0
    pub filter: f64,
    model: Human,
    /// the mass matrix' buffer (its first entry the body's mass)
    m: Vec<f64>,
}

impl Balanced {
    /// `tracking` with its `balance` set, the placement filtered over `filter` seconds.
    pub fn new(model: &Human, tracking: Tracking, filter: f64) -> Result<Balanced, String> {
        if tracking.balance.is_none() {
            return Err("Balanced needs a tracking with its `balance` set".into());
        }
        if !(filter > 0.0 && filter.is_finite()) {
            return Err(format!(
                "the balance's filter time {filter} s must be positive and finite"
            ));
        }
        Ok(Balanced {
            tracking,
            filter,
            model: model.clone(),
            m: vec![0.0; Human::NQ * Human::NQ],
        })
    }
}

impl Efforts for Balanced {
    const NX: usize = 6;
    const STATE_NAMES: &'static [&'static str] = &[
        "balance:hip_flexion[0]",
        "balance:hip_adduction[0]",
        "balance:knee[0]",
        "balance:hip_flexion[1]",
        "balance:hip_adduction[1]",
        "balance:knee[1]",
    ];

    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        self.tracking.efforts(e)?;
        if let Some(b) = &self.tracking.balance {
            for (k, (_, _, joints)) in b.legs.iter().enumerate() {
                for (c, j) in joints.iter().enumerate() {
                    e.generalized_force(*j, self.tracking.kp * e.x[3 * k + c]);
                }
            }
        }
        Ok(())
    }

    fn state_derivatives(&mut self, e: &Effort, xd: &mut [f64]) -> Result<(), String> {
        let Some(b) = &self.tracking.balance else {
            xd.fill(0.0);
            return Ok(());
        };
        self.model.set_chart(0, e.chart(0));
        self.model.mass_matrix(e.t, e.q, &mut self.m);
        let (g, p) = mass_centre(&self.model, e.q, e.qd, &self.m);
        let v = p.map(|p| p / self.m[0]);
        let target = b.placement_changes(self.tracking.reference.period, e.t, e.kin, g, v);
        for (i, x) in xd.iter_mut().enumerate() {
            *x = (target[i / 3][i % 3] - e.x[i]) / self.filter;
        }
        Ok(())
    }
}

/// The 3 × 3 matrix of a frame's Jacobian `j` (3 × NQ, column-major) in the coordinates
/// `joints`.
fn columns(j: &[f64], joints: &[usize; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|c| j[3 * joints[c] + i]))
}

/// A foot's sole: the mean of its ellipsoids' support points, position and velocity.
fn sole(foot: [([f64; 3], [f64; 3]); 6]) -> ([f64; 3], [f64; 3]) {
    let mut m = ([0.0; 3], [0.0; 3]);
    for (x, v) in foot {
        for j in 0..3 {
            m.0[j] += x[j] / 6.0;
            m.1[j] += v[j] / 6.0;
        }
    }
    m
}

/// The solution of the 3 × 3 system a x = b by Cramer's rule, `None` where a is singular.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    if d.abs() < 1e-12 {
        return None;
    }
    Some(std::array::from_fn(|c| {
        let mut m = a;
        for (row, v) in m.iter_mut().zip(b) {
            row[c] = v;
        }
        det(m) / d
    }))
}

/// The contact ellipsoids of one foot, as in the model: point name and semi-axes.
pub const FOOT_ELLIPSOIDS: [(&str, [f64; 3]); 6] = [
    ("heel", [0.035, 0.03, 0.025]),
    ("midfoot", [0.03, 0.015, 0.015]),
    ("meta1", [0.02, 0.015, 0.015]),
    ("meta5", [0.02, 0.015, 0.012]),
    ("hallux", [0.025, 0.008, 0.012]),
    ("lesser_toes", [0.02, 0.008, 0.015]),
];

/// The support point of each of the 12 ellipsoids (feet k = 0, 1, in `FOOT_ELLIPSOIDS`'
/// order) at the kinematics `kin`: its world position and velocity (the material point's).
pub fn support_points(model: &Human, kin: &Kinematics) -> [[([f64; 3], [f64; 3]); 6]; 2] {
    Feet::of(model.info()).support_points(kin)
}

/// Where the feet's ellipsoids are in a model's kinematics: their centres' points and the
/// frames whose axes they follow.
#[derive(Clone, Copy, Debug)]
pub struct Feet {
    point: [[usize; 6]; 2],
    frame: [[usize; 6]; 2],
}

impl Feet {
    pub fn of(info: &mbs::ModelInfo) -> Feet {
        let index = |k: usize, e: usize| {
            let name = FOOT_ELLIPSOIDS[e].0;
            let frame = if name == "hallux" || name == "lesser_toes" {
                "toes_o"
            } else {
                "calcn_o"
            };
            (
                info.point_index(&format!("{name}[{k}]"))
                    .expect("the foot's points"),
                info.frame_index(&format!("{frame}[{k}]"))
                    .expect("the foot's frames"),
            )
        };
        Feet {
            point: std::array::from_fn(|k| std::array::from_fn(|e| index(k, e).0)),
            frame: std::array::from_fn(|k| std::array::from_fn(|e| index(k, e).1)),
        }
    }

    /// See [`support_points`].
    pub fn support_points(&self, kin: &Kinematics) -> [[([f64; 3], [f64; 3]); 6]; 2] {
        std::array::from_fn(|k| {
            std::array::from_fn(|e| {
                let axes = FOOT_ELLIPSOIDS[e].1;
                let (pt, fr) = (&kin.points[self.point[k][e]], &kin.frames[self.frame[k][e]]);
                let ellipsoid = Ellipsoid {
                    centre: pt.position,
                    rotation: &fr.pose.rotation,
                    axes,
                };
                let arm = ellipsoid.reach([0.0, 1.0, 0.0]);
                let x = [0, 1, 2].map(|j| pt.position[j] + arm[j]);
                let w = fr.angular_velocity;
                let v = [
                    pt.velocity[0] + w[1] * arm[2] - w[2] * arm[1],
                    pt.velocity[1] + w[2] * arm[0] - w[0] * arm[2],
                    pt.velocity[2] + w[0] * arm[1] - w[1] * arm[0],
                ];
                (x, v)
            })
        })
    }
}

/// An efforts part `E` of the human model with the feet's twelve ellipsoids also on the
/// boxes of a [`Terrain`] ([`mbs::terrain`]), by the law of the generated contacts with the
/// ground y = 0 (the model's `k_foot`, `d_foot`, `mu_foot`, `eps_foot`, Hertz's exponent
/// 1.5), which stay: the terrain is the boxes alone.
#[derive(Clone, Debug)]
pub struct OnTerrain<E> {
    pub inner: E,
    pub terrain: Terrain,
    feet: Feet,
}

impl<E: Efforts> OnTerrain<E> {
    /// `inner` with `model`'s feet also on `blocks` (footprints along x and z).
    pub fn new(model: &Human, inner: E, blocks: Vec<Block>) -> OnTerrain<E> {
        let p = model.params();
        let law = mbs::terrain::ContactLaw {
            k: p.k_foot,
            c: 0.0,
            exponent: 1.5,
            dissipation: p.d_foot,
            mu: p.mu_foot,
            eps: p.eps_foot,
        };
        let terrain = Terrain {
            up: mbs::terrain::Vertical::Y,
            ground: false,
            blocks,
            law,
        };
        OnTerrain {
            inner,
            terrain,
            feet: Feet::of(model.info()),
        }
    }

    /// Each foot's total force from the boxes (world axes) at the kinematics `kin` (frames
    /// set).
    pub fn forces(&self, kin: &Kinematics) -> [[f64; 3]; 2] {
        std::array::from_fn(|k| {
            let mut total = [0.0; 3];
            for (e, (_, axes)) in FOOT_ELLIPSOIDS.iter().enumerate() {
                let (pt, fr) = (
                    &kin.points[self.feet.point[k][e]],
                    &kin.frames[self.feet.frame[k][e]],
                );
                let centre = (pt.position, pt.velocity);
                self.terrain.ellipsoid_forces(
                    &fr.pose.rotation,
                    fr.angular_velocity,
                    centre,
                    *axes,
                    |_, f| total = [0, 1, 2].map(|j| total[j] + f[j]),
                );
            }
            total
        })
    }
}

impl<E: Efforts> Efforts for OnTerrain<E> {
    const NX: usize = E::NX;
    const STATE_NAMES: &'static [&'static str] = E::STATE_NAMES;

    fn initial_states(&self, x: &mut [f64]) {
        self.inner.initial_states(x)
    }

    fn reads_jacobians(&self) -> bool {
        self.inner.reads_jacobians()
    }

    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        self.inner.efforts(e)?;
        for k in 0..2 {
            for (j, (name, axes)) in FOOT_ELLIPSOIDS.iter().enumerate() {
                let (point, frame) = (self.feet.point[k][j], self.feet.frame[k][j]);
                let pressed = self.terrain.apply_ellipsoid(e, frame, point, *axes);
                // as the guard does for the ground (`Guard::check`)
                let thin = axes.iter().copied().fold(f64::INFINITY, f64::min);
                if pressed.depth > thin {
                    return Err(e.reject(format!(
                        "the ellipsoid {name}[{k}] is {:.4} m into a box of the terrain, deeper than its smallest semi-axis ({thin} m): it has passed through the box",
                        pressed.depth
                    )));
                }
            }
        }
        Ok(())
    }

    fn state_derivatives(&mut self, e: &Effort, xd: &mut [f64]) -> Result<(), String> {
        self.inner.state_derivatives(e, xd)
    }
}

/// The knee splines' tables span [−KNEE_TABLE, KNEE_TABLE] (rad).
pub const KNEE_TABLE: f64 = 2.0944;

/// What a run of the model must not do silently, checked at every evaluation of the parts
/// that drive it ([`Tracking`], [`PassiveJoints`]): a knee beyond its splines' tables (the
/// tibia's translation would be extrapolated), an ellipsoid deeper in the ground than its
/// smallest semi-axis (the foot has passed through the ground), and the origin of the
/// pelvis, the torso, a hip or a knee below the ground (only the feet meet the ground: a
/// body that falls goes through it). Each is an `Err` naming the coordinate, the ellipsoid
/// or the frame. In a run ([`Guard::apply`]) it rejects the state
/// ([`mbs::Effort::reject`]): an overshooting trial state of a large step is retried smaller,
/// and a motion that really goes there stops with `Failure::EffortRejected`, trajectory
/// kept.
#[derive(Clone, Copy, Debug)]
pub struct Guard {
    feet: Feet,
    knees: [usize; 2],
    /// the frames above the feet that must stay above the ground, and their names
    above: [(usize, &'static str); 6],
}

impl Guard {
    pub fn new(info: &mbs::ModelInfo) -> Result<Guard, String> {
        Ok(Guard {
            feet: Feet::of(info),
            knees: [dof_index(info, "knee[0]")?, dof_index(info, "knee[1]")?],
            above: {
                let frame = |name: &'static str| {
                    info.frame_index(name)
                        .map(|i| (i, name))
                        .ok_or_else(|| format!("the model has no frame `{name}`"))
                };
                [
                    frame("pelvis_o")?,
                    frame("torso")?,
                    frame("femur_o[0]")?,
                    frame("femur_o[1]")?,
                    frame("tibia_o[0]")?,
                    frame("tibia_o[1]")?,
                ]
            },
        })
    }

    /// [`Guard::check`] at the state of `e`, a failure rejecting that state.
    pub fn apply(&self, e: &mut Effort) -> Result<(), String> {
        match self.check(e.q, e.kin) {
            Ok(()) => Ok(()),
            Err(m) => Err(e.reject(m)),
        }
    }

    /// `Err` with what went wrong, at (q, kin).
    pub fn check(&self, q: &[f64], kin: &Kinematics) -> Result<(), String> {
        for (k, &i) in self.knees.iter().enumerate() {
            if q[i].abs() > KNEE_TABLE {
                return Err(format!(
                    "knee[{k}] = {:.4} rad is beyond the knee's tables [−{KNEE_TABLE}, {KNEE_TABLE}]: the tibia's translation is not known there",
                    q[i]
                ));
            }
        }
        for (k, foot) in self.feet.support_points(kin).iter().enumerate() {
            for (e, (x, _)) in foot.iter().enumerate() {
                let (name, axes) = FOOT_ELLIPSOIDS[e];
                let thin = axes.iter().copied().fold(f64::INFINITY, f64::min);
                if -x[1] > thin {
                    return Err(format!(
                        "the ellipsoid {name}[{k}] is {:.4} m into the ground, deeper than its smallest semi-axis ({thin} m): it has passed through the ground",
                        -x[1]
                    ));
                }
            }
        }
        for (i, name) in self.above {
            let y = kin.frames[i].pose.position[1];
            if y < 0.0 {
                return Err(format!(
                    "the frame {name} is {:.1e} m below the ground: the body has fallen through it (only the feet's ellipsoids meet the ground)",
                    -y
                ));
            }
        }
        Ok(())
    }
}

/// The force of the ground on each foot (world axes) at a state, recomputed from the
/// motion of the feet with the model's contact law (for reports: the dynamics use the
/// generated code); `kin` holds that motion after ([`Model::motion`]: no Jacobians).
pub fn ground_forces(
    model: &Human,
    t: f64,
    q: &[f64],
    qd: &[f64],
    kin: &mut Kinematics,
) -> [[f64; 3]; 2] {
    model.motion(t, q, qd, kin);
    let p = model.params();
    let sp = support_points(model, kin);
    let mut out = [[0.0; 3]; 2];
    for (foot, points) in out.iter_mut().zip(&sp) {
        for (x, v) in points {
            let delta = -x[1];
            if delta <= 0.0 {
                continue;
            }
            let fn_ = (p.k_foot * delta.powf(1.5) * (1.0 - p.d_foot * v[1])).max(0.0);
            let vt = [v[0], 0.0, v[2]];
            let r2 = (vt[0] * vt[0] + vt[2] * vt[2] + p.eps_foot * p.eps_foot).sqrt();
            let c = -p.mu_foot * fn_ / r2;
            foot[0] += c * vt[0];
            foot[1] += fn_;
            foot[2] += c * vt[2];
        }
    }
    out
}

/// The start of the last whole cycle of `tr` (cycles of `period` from t = 0; the cycles
/// before it are the start's transient).
pub fn last_cycle_start(tr: &mbs::Trajectory, period: f64) -> f64 {
    let end = tr.t.last().copied().unwrap_or(0.0);
    ((end / period).round() - 1.0).max(0.0) * period
}

/// The output instants of the last whole cycle of `tr` (see [`last_cycle_start`]), which
/// must be uniform over it (`Output::Every` at a step dividing `period`) and more than
/// 2 `harmonics`: the samples a Fourier fit of that many harmonics takes.
pub(crate) fn last_cycle_rows(
    tr: &mbs::Trajectory,
    period: f64,
    harmonics: usize,
) -> Result<Vec<usize>, String> {
    let start = last_cycle_start(tr, period);
    let rows: Vec<usize> = (0..tr.len())
        .filter(|i| tr.t[*i] >= start - 1e-9 && tr.t[*i] < start + period - 1e-9)
        .collect();
    let dt = period / rows.len().max(1) as f64;
    let end = tr.t.last().copied().unwrap_or(0.0);
    let uniform = rows.len() > 2 * harmonics
        && end >= start + period - 1e-9
        && rows
            .iter()
            .enumerate()
            .all(|(k, i)| (tr.t[*i] - start - k as f64 * dt).abs() < 1e-6);
    if !uniform {
        return Err(format!(
            "the run must cover a whole cycle of {period} s sampled uniformly (Output::Every at \
             a step dividing it), more than {} outputs over it; it ends at t = {end} s, {} \
             outputs in its last cycle",
            2 * harmonics,
            rows.len()
        ));
    }
    Ok(rows)
}

/// What a gait laboratory reads from the last cycle of a mode-1 run: the ground reaction
/// forces of both feet over the cycle, the vertical impulse, the flight time and the
/// residual torque on the pelvis.
#[derive(Clone, Debug)]
pub struct CycleForces {
    /// per output instant of the cycle: cycle % (0 at the right heel strike), the right and
    /// the left foot's force (world axes, body weights)
    pub grf: Vec<(f64, [f64; 3], [f64; 3])>,
    /// the vertical impulse over weight × time (1 when the body neither rises nor sinks)
    pub impulse_ratio: f64,
    /// the fraction of the cycle with no foot on the ground (less than 1 % of weight)
    pub airborne: f64,
    /// the residual torque on the pelvis: rms and peak (N·m)
    pub residual_rms: f64,
    pub residual_peak: f64,
    /// the residual torque's rms about each world axis: fore–aft (roll), vertical (yaw),
    /// lateral (pitch) (N·m)
    pub residual_axes: [f64; 3],
    /// the fraction of the cycle the trajectory covers (1 unless the run stopped)
    pub covered: f64,
    /// per foot, how it came down at its heel strike: of its landings (its vertical force
    /// rising through 2 % of weight) from 5 % of the cycle before its start, the nearest to
    /// the foot's heel strike in the reference (0 % for the right, 50 % for the left), the
    /// velocity of its lowest point at the last output instant before (fore–aft, vertical,
    /// lateral; m/s); `None` where it did not land
    pub landing: [Option<[f64; 3]>; 2],
}

/// One foot's figures over its own cycle (0 % at its heel strike), in body weights: the
/// vertical force's first peak (0–30 %), trough (20–45 %) and second peak (35–62 %); the
/// fore–aft force's least over 0–30 % (braking) and largest over 35–62 % (propulsion), and
/// its means over the stance's halves (0–31 %, 31–62 %: braking then propulsion when the
/// first is negative and the second positive). `None` where the run did not reach.
#[derive(Clone, Copy, Debug)]
pub struct FootFigures {
    pub first_peak: Option<f64>,
    pub trough: Option<f64>,
    pub second_peak: Option<f64>,
    pub braking: Option<f64>,
    pub propulsion: Option<f64>,
    pub first_half: Option<f64>,
    pub second_half: Option<f64>,
}

impl CycleForces {
    /// The figures of the last whole cycle of `tr` ([`last_cycle_start`]), `tr` a run of
    /// [`Tracking`] on `model` (its first `Human::NQ` coordinates), `weight` the body's
    /// weight (N).
    pub fn of(
        model: &Human,
        tracking: &Tracking,
        tr: &mbs::Trajectory,
        weight: f64,
    ) -> CycleForces {
        let n = Human::NQ;
        let mut kin = Kinematics::new::<Human>();
        let period = tracking.reference.period;
        let end = tr.t.last().copied().unwrap_or(0.0);
        let start = last_cycle_start(tr, period);
        let (mut grf, mut impulse, mut airborne, mut r2, mut rmax) =
            (Vec::new(), 0.0, 0.0, 0.0, 0.0f64);
        let mut axes2 = [0.0; 3];
        let mut last: Option<(f64, f64)> = None;
        let mut model = model.clone();
        // per foot: the landing nearest its heel strike so far, its distance (cycles)
        let mut landing: [Option<(f64, [f64; 3])>; 2] = [None; 2];
        // per foot: its vertical force and its lowest point's velocity at the instant before
        let mut before: [Option<(f64, [f64; 3])>; 2] = [None; 2];
        for i in (0..tr.len()).filter(|i| tr.t[*i] >= start - 0.05 * period - 1e-9) {
            let (q, qd) = (&tr.q(i)[..n], &tr.qd(i)[..n]);
            // the pelvis' angles in the chart the run read them in
            mbs::charts::use_charts_of(&mut model, tr, i);
            let f = ground_forces(&model, tr.t[i], q, qd, &mut kin);
            for (k, points) in support_points(&model, &kin).iter().enumerate() {
                let low = points.iter().min_by(|a, b| a.0[1].total_cmp(&b.0[1]));
                let v = low.map_or([0.0; 3], |(_, v)| *v);
                if let Some((fy, v0)) = before[k] {
                    if fy < 0.02 * weight && f[k][1] >= 0.02 * weight {
                        let u = ((tr.t[i] - start) / period - 0.5 * k as f64).rem_euclid(1.0);
                        let d = u.min(1.0 - u);
                        if landing[k].is_none_or(|(d0, _)| d < d0) {
                            landing[k] = Some((d, v0));
                        }
                    }
                }
                before[k] = Some((f[k][1], v));
            }
            if tr.t[i] < start - 1e-9 {
                continue;
            }
            let torque = tracking.pelvis_torque(tr.t[i], &kin);
            let r = torque.iter().map(|x| x * x).sum::<f64>().sqrt();
            let bw = |v: [f64; 3]| v.map(|x| x / weight);
            grf.push((100.0 * (tr.t[i] - start) / period, bw(f[0]), bw(f[1])));
            let vertical = f[0][1] + f[1][1];
            if let Some((t0, v0)) = last {
                let dt = tr.t[i] - t0;
                impulse += 0.5 * (vertical + v0) * dt;
                if vertical < 0.01 * weight {
                    airborne += dt;
                }
                r2 += r * r * dt;
                for (a, m) in axes2.iter_mut().zip(torque) {
                    *a += m * m * dt;
                }
            }
            last = Some((tr.t[i], vertical));
            rmax = rmax.max(r);
        }
        let t = (end - start).max(1e-12);
        CycleForces {
            grf,
            impulse_ratio: impulse / (weight * t),
            airborne: airborne / t,
            residual_rms: (r2 / t).sqrt(),
            residual_peak: rmax,
            residual_axes: axes2.map(|a| (a / t).sqrt()),
            covered: (t / period).min(1.0),
            landing: landing.map(|l| l.map(|(_, v)| v)),
        }
    }

    /// Foot `k`'s force over its own cycle: (its cycle %, force), in time order of the run.
    fn foot(&self, k: usize) -> impl Iterator<Item = (f64, [f64; 3])> + '_ {
        self.grf.iter().map(move |(p, r, l)| {
            if k == 0 {
                (*p, *r)
            } else {
                ((p + 50.0).rem_euclid(100.0), *l)
            }
        })
    }

    /// The figures of foot `k` (0 right, 1 left).
    pub fn figures(&self, k: usize) -> FootFigures {
        let extreme = |lo: f64, hi: f64, c: usize, max: bool| {
            let v = self
                .foot(k)
                .filter(|(p, _)| *p >= lo && *p <= hi)
                .map(|(_, f)| f[c]);
            if max {
                v.reduce(f64::max)
            } else {
                v.reduce(f64::min)
            }
        };
        // the trapezoidal mean over [lo, hi] of the fore–aft force, on pairs of successive
        // outputs inside the window
        let mean = |lo: f64, hi: f64| {
            let points: Vec<(f64, f64)> = self.foot(k).map(|(p, f)| (p, f[0])).collect();
            let (mut sum, mut span) = (0.0, 0.0);
            for w in points.windows(2) {
                let ((p0, f0), (p1, f1)) = (w[0], w[1]);
                if p0 >= lo && p1 <= hi && p1 > p0 {
                    sum += 0.5 * (f0 + f1) * (p1 - p0);
                    span += p1 - p0;
                }
            }
            (span > 0.0).then(|| sum / span)
        };
        FootFigures {
            first_peak: extreme(0.0, 30.0, 1, true),
            trough: extreme(20.0, 45.0, 1, false),
            second_peak: extreme(35.0, 62.0, 1, true),
            braking: extreme(0.0, 30.0, 0, false),
            propulsion: extreme(35.0, 62.0, 0, true),
            first_half: mean(0.0, 31.0),
            second_half: mean(31.0, 62.0),
        }
    }
}

/// ZYX angles (a, b, c) of a rotation R = Rz(a) Ry(b) Rx(c), the pelvis' `Tfree` angles.
fn zyx_angles(r: &[[f64; 3]; 3]) -> [f64; 3] {
    [
        r[1][0].atan2(r[0][0]),
        (-r[2][0]).clamp(-1.0, 1.0).asin(),
        r[2][1].atan2(r[2][2]),
    ]
}

/// Depth of the start: how far the lowest ellipsoid is pressed into the ground (m).
pub const START_DEPTH: f64 = 2e-3;

/// The state at the start of a cycle of `reference` (right heel strike): every joint and
/// the pelvis' orientation on their references (angles and rates), the pelvis at the height
/// where the lowest ellipsoid is [`START_DEPTH`] into the ground, and moving so that the
/// left foot's lowest support point, on the ground in its late stance, is at rest.
pub fn cycle_start(model: &Human, reference: &GaitReference) -> (Vec<f64>, Vec<f64>) {
    let (mut q, mut qd) = reference_state(model, reference, 0.0);
    let mut kin = Kinematics::new::<Human>();
    model.motion(0.0, &q, &qd, &mut kin);
    let sp = support_points(model, &kin);
    let lowest = sp
        .iter()
        .flatten()
        .map(|(x, _)| x[1])
        .fold(f64::INFINITY, f64::min);
    q[1] -= lowest + START_DEPTH;
    let v = walking_speed(model, reference);
    qd[0] = v;
    qd[1] = 0.0;
    qd[2] = 0.0;
    (q, qd)
}

/// The walking speed the reference implies: how fast the right midfoot moves backward
/// relative to a pelvis moving with its reference orientation only, averaged over the flat
/// part of the right foot's stance (15 % to 40 % of the cycle).
pub fn walking_speed(model: &Human, reference: &GaitReference) -> f64 {
    let mut kin = Kinematics::new::<Human>();
    let feet = Feet::of(model.info());
    let samples = 11;
    let mut sum = 0.0;
    for s in 0..samples {
        let phase = reference.period * (0.15 + 0.25 * s as f64 / (samples - 1) as f64);
        let t = phase - reference.offset;
        let (q, qd) = reference_state(model, reference, t);
        model.motion(t, &q, &qd, &mut kin);
        sum -= feet.support_points(&kin)[0][1].1[0];
    }
    sum / samples as f64
}

/// The model's state on `reference` at `t`: every joint and the pelvis' orientation on
/// their references (angles and rates; the pelvis' ZYX rates by central differences of its
/// angles), the pelvis' translation at the model's start and at rest.
pub fn reference_state(model: &Human, reference: &GaitReference, t: f64) -> (Vec<f64>, Vec<f64>) {
    let n = Human::NQ;
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    qd.fill(0.0);
    for (k, (i, _)) in reference.joints.iter().enumerate() {
        let [r, rd, _] = reference.joint(k, t);
        q[*i] = r;
        qd[*i] = rd;
    }
    let dt = 1e-6;
    let ang = |t: f64| zyx_angles(&reference.pelvis_rotation(t));
    let (a0, ap, am) = (ang(t), ang(t + dt), ang(t - dt));
    for j in 0..3 {
        q[3 + j] = a0[j];
        qd[3 + j] = (ap[j] - am[j]) / (2.0 * dt);
    }
    (q, qd)
}

/// The passive moment of one joint (Anderson 1999, as transcribed in Falisse et al. 2019's
/// code): M(q, q̇) = K1 exp(K2 (q − θ2)) + K3 exp(K4 (q − θ1)) − d q̇, N·m on the coordinate,
/// stiff beyond the range [θ1, θ2] and nearly free inside it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassiveLaw {
    pub k: [f64; 4],
    /// lower and upper ends of the range (rad)
    pub range: [f64; 2],
}

impl PassiveLaw {
    /// The elastic part K1 exp(K2 (q − θ2)) + K3 exp(K4 (q − θ1)).
    pub fn elastic(&self, q: f64) -> f64 {
        let [k1, k2, k3, k4] = self.k;
        k1 * (k2 * (q - self.range[1])).exp() + k3 * (k4 * (q - self.range[0])).exp()
    }
}

/// The laws of the model's joints, in gait2392's conventions (the model's own): coordinate
/// name (leg k written `[k]`), K1..K4, θ1, θ2. Source: antoinefalisse/3dpredictsim,
/// `PassiveMoments/PassiveMomentsData.m` (the same numbers in KULeuvenNeuromechanics/PredSim
/// and stanfordnmbl/opencap-processing), credited to F. C. Anderson's 1999 thesis.
pub const PASSIVE_LAWS: [(&str, PassiveLaw); 10] = [
    (
        "hip_flexion",
        law([-2.44, 5.05, 1.51, -21.88], [-0.6981, 1.81]),
    ),
    (
        "hip_adduction",
        law([-0.03, 14.94, 0.03, -14.94], [-0.5, 0.5]),
    ),
    (
        "hip_rotation",
        law([-0.03, 14.94, 0.03, -14.94], [-0.92, 0.92]),
    ),
    ("knee", law([-6.09, 33.94, 11.03, -11.33], [-2.4, 0.13])),
    ("ankle", law([-2.03, 38.11, 0.18, -12.12], [-0.74, 0.52])),
    (
        "subtalar",
        law([-60.21, 16.32, 60.21, -16.32], [-0.65, 0.65]),
    ),
    (
        "mtp",
        law([-0.9, 14.87, 0.18, -70.08], [0.0, 1.134_464_013_796_31]),
    ),
    (
        "lumbar_extension",
        law(
            [-0.35, 30.72, 0.25, -20.36],
            [-0.523_598_775_598_298_8, 0.17],
        ),
    ),
    (
        "lumbar_bending",
        law(
            [-0.25, 20.36, 0.25, -20.36],
            [-0.349_065_850_398_865_9, 0.349_065_850_398_865_9],
        ),
    ),
    (
        "lumbar_rotation",
        law(
            [-0.25, 20.36, 0.25, -20.36],
            [-0.349_065_850_398_865_9, 0.349_065_850_398_865_9],
        ),
    ),
];

const fn law(k: [f64; 4], range: [f64; 2]) -> PassiveLaw {
    PassiveLaw { k, range }
}

/// Names of the passive moments' states (their viscous parts), in [`TRACKED`]'s order.
const PASSIVE_STATES: [&str; 17] = [
    "viscous:lumbar_extension",
    "viscous:lumbar_bending",
    "viscous:lumbar_rotation",
    "viscous:hip_flexion[0]",
    "viscous:hip_adduction[0]",
    "viscous:hip_rotation[0]",
    "viscous:knee[0]",
    "viscous:ankle[0]",
    "viscous:subtalar[0]",
    "viscous:mtp[0]",
    "viscous:hip_flexion[1]",
    "viscous:hip_adduction[1]",
    "viscous:hip_rotation[1]",
    "viscous:knee[1]",
    "viscous:ankle[1]",
    "viscous:subtalar[1]",
    "viscous:mtp[1]",
];

/// Passive joint moments with a differential equation per joint: on each of the 17 joints the
/// law's elastic moment K1 exp(K2 (q − θ2)) + K3 exp(K4 (q − θ1)) acts at once, and its
/// viscous moment v is a state that relaxes toward −d q̇ with a time constant T,
/// v̇ = −(v + d q̇) / T (a Maxwell element, spring d/T in series with the damper d, in
/// parallel with the elastic law: tissue whose damping has memory; T → 0 gives the law's
/// −d q̇). Delaying the elastic part instead would pump energy into a joint pressed against
/// its stiff range end (an effective damping d − k T < 0). Optionally with a [`Tracking`] of a
/// gait cycle on top. A model wrapped without it (`WithEfforts<Human, Tracking>`) has neither the moments nor
/// their states.
#[derive(Clone, Debug)]
pub struct PassiveJoints {
    /// (coordinate of the model, its law), in `TRACKED`'s order
    pub joints: Vec<(usize, PassiveLaw)>,
    /// viscous damping d (N·m·s/rad) of every joint
    pub damping: f64,
    /// time constant T of the moments' relaxation (s)
    pub time_constant: f64,
    pub tracking: Option<Tracking>,
    pub guard: Guard,
}

impl PassiveJoints {
    /// The laws of [`PASSIVE_LAWS`] on the coordinates of `info`, with damping `damping`
    /// (Falisse et al. used 0.1 N·m·s/rad in PredSim, 0.001 in their 2019 code) and time
    /// constant `time_constant`.
    pub fn new(info: &mbs::ModelInfo, damping: f64, time_constant: f64) -> Result<Self, String> {
        let mut joints = Vec::new();
        for (dof, _) in TRACKED {
            let base = dof.split('[').next().expect("a name");
            let (_, l) = PASSIVE_LAWS
                .iter()
                .find(|(n, _)| *n == base)
                .ok_or_else(|| format!("no passive law for `{dof}`"))?;
            let i = dof_index(info, dof)?;
            joints.push((i, *l));
        }
        Ok(PassiveJoints {
            joints,
            damping,
            time_constant,
            tracking: None,
            guard: Guard::new(info)?,
        })
    }

    /// The viscous moments −d q̇ of the 17 joints: the states of a run that begins relaxed.
    pub fn relaxed(&self, qd: &[f64]) -> Vec<f64> {
        self.joints
            .iter()
            .map(|(i, _)| -self.damping * qd[*i])
            .collect()
    }

    /// The passive moment on joint `k` (in `TRACKED`'s order) at coordinate `q`, with
    /// viscous state `v`.
    pub fn moment(&self, k: usize, q: f64, v: f64) -> f64 {
        self.joints[k].1.elastic(q) + v
    }
}

impl Efforts for PassiveJoints {
    const NX: usize = 17;
    const STATE_NAMES: &'static [&'static str] = &PASSIVE_STATES;

    fn reads_jacobians(&self) -> bool {
        self.tracking.as_ref().is_some_and(|t| t.reads_jacobians())
    }

    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        if self.tracking.is_none() {
            self.guard.apply(e)?;
        }
        for (k, (i, l)) in self.joints.iter().enumerate() {
            let m = l.elastic(e.q[*i]) + e.x[k];
            e.generalized_force(*i, m);
        }
        match &mut self.tracking {
            Some(t) => t.efforts(e),
            None => Ok(()),
        }
    }

    fn state_derivatives(&mut self, e: &Effort, xd: &mut [f64]) -> Result<(), String> {
        for (k, (i, _)) in self.joints.iter().enumerate() {
            xd[k] = -(e.x[k] + self.damping * e.qd[*i]) / self.time_constant;
        }
        Ok(())
    }
}
