//! Terrain of ground and boxes (`mbs::terrain`) touched by points and by ellipsoids:
//!
//! - a point follows the usual rule (inside a box, its nearest face; the ground below it),
//!   and a sphere against a box's side and top gives the depths and forces worked by hand;
//! - a tilted ellipsoid's support point lies on its surface with its normal along the face's
//!   (the closed form checked against the ellipsoid's own equation), and its force on a box's
//!   top, with damping and friction, equals the law worked from that point;
//! - beside a box's edge or corner, behind the planes of its faces, a sphere touches the box
//!   only when it reaches the edge or the corner, at the depth and along the normal its
//!   distance to them gives, and a tilted ellipsoid there takes the way out the largest
//!   separation of the box's and the ellipsoid's support functions gives, against that
//!   function sampled over the unit sphere;
//! - an ellipsoid off its body's centre of mass, on the ground or on a box's top, gives the
//!   same generalised forces as the generated contact (`contact(…, ellipsoid = …)`) with the
//!   same plane, at 40 states pressed in, turning and sliding;
//! - the human model stands on a 10 cm platform on its twelve ellipsoids (`OnTerrain`: the
//!   generated contacts keep the ground, the terrain adds the box): the platform carries its
//!   weight, half on each foot, and the motion is the stance on the ground raised by the
//!   platform's height; started 3 cm into the platform it stops with `EffortRejected` naming
//!   the ellipsoid that passed through.

use mbs::terrain::{Block, ContactLaw, Ellipsoid, Terrain};
use mbs::{Efforts, Kinematics, Model, Options, Output, Scheme, WithEfforts};
use mbs_models::human::*;

#[path = "common/quoted.rs"]
mod quoted;

const G: f64 = 9.80665;
/// gait2392's 75.1646 kg and two patellas of 0.0862 kg (Rajagopal 2015)
const MASS: f64 = 75.1646 + 2.0 * 0.0862;

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|j| (a[j] - b[j]).abs() <= tol)
}

#[test]
fn a_point_takes_its_nearest_face_and_a_sphere_touches_a_box_as_by_hand() {
    // a step 5 cm high from x = 0.6 to 3.6, y from −1 to 1
    let t = Terrain::step(0.6, 0.05);
    assert_eq!(t.height([0.7, 0.0]), 0.05);
    assert_eq!(t.height([0.5, 0.0]), 0.0);
    // a height to plan on: the edge rounded over 2 cm, half way up at the edge; no width,
    // the edge as it is; a width or a position that is not a number, NaN (it was the
    // ground's height, and a negative width turned the ramps inside out)
    assert_eq!(t.planned_height([0.6, 0.0], 0.02), 0.025);
    assert_eq!(t.planned_height([0.62, 0.0], 0.02), 0.05);
    assert_eq!(t.planned_height([0.7, 0.0], 0.0), 0.05);
    for (p, w) in [
        ([0.7, 0.0], -0.02),
        ([0.7, 0.0], f64::NAN),
        ([f64::NAN, 0.0], 0.02),
    ] {
        assert!(t.planned_height(p, w).is_nan(), "{p:?}, width {w}");
    }
    assert!(t.height([f64::NAN, 0.0]).is_nan());
    // inside, 1 cm below the top: the top
    let (d, n) = t.penetration([0.7, 0.0, 0.04]).expect("inside the step");
    assert!(
        (d - 0.01).abs() < 1e-15 && n == [0.0, 0.0, 1.0],
        "{d} {n:?}"
    );
    // inside, 5 mm behind the riser: the riser (outward normal −x)
    let (d, n) = t.penetration([0.605, 0.0, 0.0]).expect("inside the step");
    assert!(
        (d - 0.005).abs() < 1e-15 && n == [-1.0, 0.0, 0.0],
        "{d} {n:?}"
    );
    // below the ground before the step; above it, nothing
    let (d, n) = t.penetration([0.2, 0.3, -0.002]).expect("below the ground");
    assert!((d - 0.002).abs() < 1e-15 && n == [0.0, 0.0, 1.0]);
    assert!(t.penetration([0.2, 0.3, 0.001]).is_none());
    assert!(t.penetration([0.7, 1.2, 0.01]).is_none(), "beside the step");

    // a sphere of radius 2 cm centred 1 cm before the riser, 3 cm up, pressed against it:
    // the riser 1 cm deep (the top 4 cm, the ground not at all), the force k·δ along −x at
    // the sphere's point (0.61, 0, 0.03); at rest, no friction
    let r = 0.02;
    let sphere = Ellipsoid {
        centre: [0.59, 0.0, 0.03],
        rotation: &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        axes: [r; 3],
    };
    let mut touches = Vec::new();
    t.touches(&sphere, |x| touches.push(x));
    assert_eq!(touches.len(), 1, "{touches:?}");
    let x = touches[0];
    assert!((x.depth - 0.01).abs() < 1e-15 && x.normal == [-1.0, 0.0, 0.0]);
    assert!(close(x.point, [0.61, 0.0, 0.03], 1e-15), "{:?}", x.point);
    let mut forces = Vec::new();
    let rot = *sphere.rotation;
    t.ellipsoid_forces(
        &rot,
        [0.0; 3],
        (sphere.centre, [0.0; 3]),
        sphere.axes,
        |x, f| forces.push((x.point, f)),
    );
    assert_eq!(forces.len(), 1);
    assert!(
        close(forces[0].1, [-1e5 * 0.01, 0.0, 0.0], 1e-9),
        "{forces:?}"
    );

    // the same sphere lowered 2.5 cm, 5 mm into the ground too: both push
    let low = Ellipsoid {
        centre: [0.59, 0.0, 0.015],
        ..sphere
    };
    let mut touches = Vec::new();
    t.touches(&low, |x| touches.push((x.depth, x.normal)));
    touches.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert_eq!(touches.len(), 2, "{touches:?}");
    assert!((touches[0].0 - 0.005).abs() < 1e-15 && touches[0].1 == [0.0, 0.0, 1.0]);
    assert!((touches[1].0 - 0.01).abs() < 1e-15 && touches[1].1 == [-1.0, 0.0, 0.0]);
}

/// Beside a box's edge or corner, behind the planes of both (or all three) faces, a sphere
/// touches the box only if it reaches the edge or the corner: at the depth r − (its centre's
/// distance to them), along the line from them to its centre. (Taken face by face, the
/// first sphere was 4 mm behind both the riser and the top, and the second 8 mm.) Rolled off
/// the top over the edge, 5 mm in, its depth and normal change continuously.
#[test]
fn a_sphere_beside_an_edge_or_a_corner_touches_it_as_its_distance_says() {
    // the step's top edge runs along y at x = 0.6, z = 0.05; its corner at y = −1
    let t = Terrain::step(0.6, 0.05);
    let r = 0.02;
    let at = |centre: [f64; 3]| {
        let sphere = Ellipsoid {
            centre,
            rotation: &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            axes: [r; 3],
        };
        let mut touches = Vec::new();
        t.touches(&sphere, |x| touches.push(x));
        touches
    };
    // 1.6 cm out along both faces: 2.26 cm from the edge, clear of it
    assert!(at([0.6 - 0.016, 0.0, 0.05 + 0.016]).is_empty());
    let s2 = std::f64::consts::FRAC_1_SQRT_2;
    let s3 = 1.0 / 3f64.sqrt();
    for (centre, edge, normal) in [
        // 1.2 cm out along both faces: 1.70 cm from the edge
        ([0.588, 0.3, 0.062], [0.6, 0.3, 0.05], [-s2, 0.0, s2]),
        // 1 cm out along the three faces from the corner: 1.73 cm from it
        ([0.59, -1.01, 0.06], [0.6, -1.0, 0.05], [-s3, -s3, s3]),
    ] {
        let touches = at(centre);
        assert_eq!(touches.len(), 1, "{touches:?}");
        let x = touches[0];
        let d = (0..3)
            .map(|j| (centre[j] - edge[j]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!((x.depth - (r - d)).abs() < 1e-15, "{x:?}: depth {}", r - d);
        assert!(close(x.normal, normal, 1e-12), "{x:?}");
        let point = [0, 1, 2].map(|j| centre[j] - r * normal[j]);
        assert!(close(x.point, point, 1e-12), "{x:?}");
        // at rest, the law's force along that normal
        let mut forces = Vec::new();
        let rot = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        t.ellipsoid_forces(&rot, [0.0; 3], (centre, [0.0; 3]), [r; 3], |_, f| {
            forces.push(f)
        });
        let f = normal.map(|n| 1e5 * (r - d) * n);
        assert!(forces.len() == 1 && close(forces[0], f, 1e-9), "{forces:?}");
    }
    // pressed 5 mm into the top and rolled off it over the edge: the depth and the normal
    // go continuously from the top's (5 mm, up) to the edge's (r − distance, from the edge)
    let z = 0.05 + r - 0.005;
    for k in 0..=40 {
        let x = 0.61 - 0.001 * k as f64;
        let touches = at([x, 0.0, z]);
        let (dx, dz) = ((x - 0.6).min(0.0), z - 0.05);
        let d = (dx * dx + dz * dz).sqrt();
        if d >= r {
            assert!(touches.is_empty(), "{x}: {touches:?}");
            continue;
        }
        assert_eq!(touches.len(), 1, "{x}: {touches:?}");
        let t = touches[0];
        assert!(
            (t.depth - (r - d)).abs() < 1e-15,
            "{x}: {t:?} against {}",
            r - d
        );
        assert!(close(t.normal, [dx / d, 0.0, dz / d], 1e-12), "{x}: {t:?}");
    }
}

/// A tilted ellipsoid against a box's edge and corner: the way out the terrain finds is the
/// largest separation n·(x − c) − Σ hᵢ|nᵢ| − √(nᵀ R D² Rᵀ n) over the unit sphere, against
/// that function sampled on a grid of 400 × 800 directions (then refined around the best):
/// the depths agree to 1e-9 m and the normals to 1e-4, and where every direction's
/// separation is positive there is no touch, though the ellipsoid is behind the planes of
/// both faces at the edge (the face-by-face rule's contact).
#[test]
fn a_tilted_ellipsoid_at_an_edge_takes_the_shortest_way_out() {
    let t = Terrain {
        blocks: vec![Block {
            min: [0.5, -0.5],
            max: [1.5, 0.5],
            height: 0.1,
        }],
        ground: false,
        ..Terrain::default()
    };
    let (c, h) = ([1.0, 0.0, 0.05], [0.5, 0.5, 0.05]);
    let axes = [0.03, 0.015, 0.01];
    // R = Rz(0.7) Rx(0.4)
    let r = matmul(rz(0.7), rx(0.4));
    let sep = |x: [f64; 3], n: [f64; 3]| separation((c, h), (x, &r, axes), n);
    let largest = |x: [f64; 3]| largest_separation(|n| sep(x, n), (400, 800), 1e-9);
    for (x, touching) in [
        // beside the edge x = 0.5, z = 0.1 (along y), behind both faces' planes
        ([0.5 - 0.008, 0.1, 0.1 + 0.004], true),
        ([0.5 - 0.02, 0.1, 0.1 + 0.009], false),
        // at the corner (0.5, 0.5, 0.1)
        ([0.5 - 0.006, 0.5 + 0.004, 0.1 + 0.005], true),
        // on the top, away from the edges: a face
        ([1.0, 0.0, 0.1 + 0.005], true),
    ] {
        let e = Ellipsoid {
            centre: x,
            rotation: &r,
            axes,
        };
        let mut touches = Vec::new();
        t.touches(&e, |x| touches.push(x));
        let (s, n) = largest(x);
        println!(
            "centre {x:?}: largest separation {s:.3e} along {n:.4?}; the terrain's: {touches:.4?}"
        );
        assert_eq!(touches.len(), touching as usize, "{x:?}: {touches:?}");
        assert_eq!(s < 0.0, touching, "{x:?}: {s}");
        // face by face, even the clear one would have touched: it is behind the top's and
        // the side's planes
        let faces = [
            [0.0, 0.0, 1.0],
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 1.0, 0.0],
        ]
        .map(|n| sep(x, n))
        .into_iter()
        .fold(f64::NEG_INFINITY, f64::max);
        assert!(faces < 0.0, "{x:?}: {faces}");
        if let Some(t) = touches.first() {
            assert!(
                (t.depth + s).abs() < 1e-9,
                "{x:?}: {} against {}",
                t.depth,
                -s
            );
            assert!(
                close(t.normal, n, 1e-4),
                "{x:?}: {:?} against {n:?}",
                t.normal
            );
        }
    }
}

/// An ellipsoid elongated across a box's edge, pressed on it deeper than half its semi-axis
/// across the edge: its shortest way out lies within the edge's cone, 26° above the side's normal
/// (15.3 mm), beside a largest separation over the whole circle that lies outside the cone.
/// The edge was skipped and the top's depth taken (20 mm straight up), and 0.1 µm further
/// out the edge's: a jump of the force in size and direction. Against the box's and the
/// ellipsoid's support functions sampled over the normals across the edge (the best
/// lies there: the centre is halfway along the edge and the axes are the box's).
#[test]
fn an_ellipsoid_pressed_deep_on_an_edge_leaves_by_its_shortest_way() {
    let t = tall_box();
    let r = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let axes = [0.05, 0.03, 0.12];
    // n = (0, cos θ, sin θ): s(θ) = n·(x − c) − h·|n| − √(nᵀQn), Q = diag(axes²)
    let (c, h) = ([0.5, 0.3, 0.15], [0.5, 0.3, 0.15]);
    let sep = |x: [f64; 3], th: f64| {
        let (sn, cs) = th.sin_cos();
        cs * (x[1] - c[1]) + sn * (x[2] - c[2])
            - h[1] * cs.abs()
            - h[2] * sn.abs()
            - (axes[1] * axes[1] * cs * cs + axes[2] * axes[2] * sn * sn).sqrt()
    };
    let largest = |x: [f64; 3]| {
        let k = 2_000_000;
        let (mut best, mut arg) = (f64::NEG_INFINITY, 0.0);
        for i in 0..k {
            let th = 2.0 * std::f64::consts::PI * i as f64 / k as f64;
            let s = sep(x, th);
            if s > best {
                (best, arg) = (s, th);
            }
        }
        let mut step = 1e-5;
        while step > 1e-13 {
            let mut moved = false;
            for d in [step, -step] {
                if sep(x, arg + d) > best {
                    (best, arg, moved) = (sep(x, arg + d), arg + d, true);
                }
            }
            if !moved {
                step *= 0.5;
            }
        }
        (best, [0.0, arg.cos(), arg.sin()])
    };
    let mut depths = Vec::new();
    for x in [[0.5, 0.6, 0.4], [0.5, 0.6000001, 0.4], [0.5, 0.59, 0.39]] {
        let e = Ellipsoid {
            centre: x,
            rotation: &r,
            axes,
        };
        let mut touches = Vec::new();
        t.touches(&e, |x| touches.push(x));
        let (s, n) = largest(x);
        println!(
            "centre {x:?}: largest separation {s:.6e} along {n:.4?}; the terrain's: {touches:.6?}"
        );
        assert_eq!(touches.len(), 1, "{touches:?}");
        let got = touches[0];
        assert!((got.depth + s).abs() < 1e-9, "{} against {}", got.depth, -s);
        assert!(close(got.normal, n, 1e-6), "{:?} against {n:?}", got.normal);
        depths.push((got.depth, got.normal));
    }
    assert!((depths[0].0 - depths[1].0).abs() < 1e-6, "{depths:?}");
    // the way out's angle above the side's normal (y), in the plane across the edge
    let above = depths[0].1[2].atan2(depths[0].1[1]).to_degrees();
    quoted::says(
        "docs/status.md",
        &[format!(
            "leaves by its shortest way, {:.1} mm at {above:.0}° above the side's normal ({:.0}° from the top's), where the edge was skipped for the top's 20 mm, and 0.1 µm further out the edge's {:.1} mm",
            1e3 * depths[0].0,
            90.0 - above,
            1e3 * depths[1].0
        )],
    );
}

/// A box entered with its corners swapped, or of no height, is not silently left out: the
/// heights are NaN and a point touches it at a NaN depth (its force NaN, which stops a run),
/// where a point inside the box meant was not touched at all.
#[test]
fn a_box_that_is_no_box_is_not_left_out_silently() {
    for b in [
        Block {
            min: [1.0, 0.0],
            max: [0.0, 0.6],
            height: 0.3,
        },
        Block {
            min: [0.0, 0.0],
            max: [1.0, 0.6],
            height: 0.0,
        },
    ] {
        let t = Terrain {
            blocks: vec![b],
            ..Terrain::default()
        };
        assert!(t.height([0.5, 0.3]).is_nan(), "{b:?}");
        assert!(t.planned_height([0.5, 0.3], 0.01).is_nan(), "{b:?}");
        let (depth, _) = t.penetration([0.5, 0.3, 0.2]).unwrap();
        assert!(depth.is_nan(), "{b:?}: {depth}");
        let f = t.point_force([0.5, 0.3, 0.2], [0.0; 3]);
        assert!(f.iter().any(|x| x.is_nan()), "{b:?}: {f:?}");
    }
    // the same box with its corners in order carries the point
    let t = Terrain {
        blocks: vec![Block {
            min: [0.0, 0.0],
            max: [1.0, 0.6],
            height: 0.3,
        }],
        ..Terrain::default()
    };
    let (depth, n) = t.penetration([0.5, 0.3, 0.2]).unwrap();
    assert!(
        (depth - 0.1).abs() < 1e-15 && n == [0.0, 0.0, 1.0],
        "{depth} {n:?}"
    );
}

/// R = Rx(θ) (columns: the body's axes in world axes).
/// An ellipsoid with a NaN semi-axis or centre is not silently let through the terrain: it
/// touches at a NaN depth, so its force is NaN and a run stops on it; a negative semi-axis
/// counts by its size (it fell outside the boxes' broad phase).
#[test]
fn a_nan_ellipsoid_is_not_let_through_and_a_negative_axis_counts_by_its_size() {
    const I: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let t = Terrain::step(0.6, 0.05);
    let forces = |axes: [f64; 3], centre: [f64; 3]| {
        let mut out = Vec::new();
        t.ellipsoid_forces(&I, [0.0; 3], (centre, [0.0; 3]), axes, |_, f| out.push(f));
        out
    };
    let nan = forces([0.02, f64::NAN, 0.02], [0.2, 0.0, 0.01]);
    assert!(
        nan.len() == 1 && nan[0].iter().all(|f| f.is_nan()),
        "{nan:?}"
    );
    // a sphere of 2 cm centred 1 cm before the riser, 3 cm up: one semi-axis written
    // negative touches the riser as the sphere does
    let sphere = forces([0.02, 0.02, 0.02], [0.59, 0.0, 0.03]);
    let negative = forces([-0.02, 0.02, 0.02], [0.59, 0.0, 0.03]);
    assert!(
        !sphere.is_empty() && sphere == negative,
        "{sphere:?} {negative:?}"
    );
}

fn rx(theta: f64) -> [[f64; 3]; 3] {
    let (s, c) = theta.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

#[test]
fn a_tilted_ellipsoid_on_a_box_top_by_hand() {
    let (a, b, c) = (0.05, 0.03, 0.02);
    let theta: f64 = 0.4;
    let r = rx(theta);
    let t = Terrain {
        blocks: vec![Block {
            min: [0.5, -0.5],
            max: [1.5, 0.5],
            height: 0.1,
        }],
        law: ContactLaw {
            k: 2e6,
            c: 10.0,
            exponent: 1.5,
            dissipation: 1.0,
            mu: 0.6,
            eps: 0.01,
        },
        ..Terrain::default()
    };
    // the lowest point of Rx(θ)·diag(a, b, c) lies s = √(b² sin²θ + c² cos²θ) below the
    // centre; centre it 3 mm less than s above the top
    let (sn, cs) = theta.sin_cos();
    let s = (b * b * sn * sn + c * c * cs * cs).sqrt();
    let depth = 0.003;
    let centre = [1.0, 0.1, 0.1 + s - depth];
    let e = Ellipsoid {
        centre,
        rotation: &r,
        axes: [a, b, c],
    };
    let mut touches = Vec::new();
    t.touches(&e, |x| touches.push(x));
    assert_eq!(touches.len(), 1, "{touches:?}");
    let x = touches[0];
    assert!(
        x.normal == [0.0, 0.0, 1.0] && (x.depth - depth).abs() < 1e-15,
        "{x:?}"
    );
    // the support point by hand: centre − (0, sinθ cosθ (b² − c²)/s, s)
    let hand = [
        centre[0],
        centre[1] - sn * cs * (b * b - c * c) / s,
        centre[2] - s,
    ];
    assert!(close(x.point, hand, 1e-15), "{:?} vs {hand:?}", x.point);
    // on the surface: y = Rᵀ(p − x) has Σ yᵢ²/aᵢ² = 1, and the surface's normal there,
    // R (yᵢ/aᵢ²), points along −z
    let d = [0, 1, 2].map(|i| x.point[i] - centre[i]);
    let y = [0, 1, 2].map(|j| (0..3).map(|i| r[i][j] * d[i]).sum::<f64>());
    let axes = [a, b, c];
    let level: f64 = (0..3).map(|j| (y[j] / axes[j]).powi(2)).sum();
    assert!((level - 1.0).abs() < 1e-14, "{level}");
    let g = [0, 1, 2].map(|j| y[j] / (axes[j] * axes[j]));
    let normal = [0, 1, 2].map(|i| (0..3).map(|j| r[i][j] * g[j]).sum::<f64>());
    assert!(normal[0].abs() < 1e-12 && normal[1].abs() < 1e-12 * normal[2].abs());
    assert!(normal[2] < 0.0);

    // moving: the centre at v, the body turning at ω; the material point at the support
    // point moves at v + ω × (p − x); the law by hand
    let v = [0.3, -0.1, -0.2];
    let w = [1.0, 2.0, -0.5];
    let vp = [
        v[0] + w[1] * d[2] - w[2] * d[1],
        v[1] + w[2] * d[0] - w[0] * d[2],
        v[2] + w[0] * d[1] - w[1] * d[0],
    ];
    let rate = -vp[2];
    let f_n = 2e6 * depth.powf(1.5) * (1.0 + rate) + 10.0 * rate;
    let slide = (vp[0] * vp[0] + vp[1] * vp[1] + 0.01 * 0.01).sqrt();
    let expect = [-0.6 * f_n * vp[0] / slide, -0.6 * f_n * vp[1] / slide, f_n];
    let mut forces = Vec::new();
    t.ellipsoid_forces(&r, w, (centre, v), [a, b, c], |x, f| {
        forces.push((x.point, f))
    });
    assert_eq!(forces.len(), 1);
    assert!(close(forces[0].0, hand, 1e-15));
    assert!(f_n > 0.0);
    assert!(
        close(forces[0].1, expect, 1e-12 * f_n),
        "{:?} vs {expect:?}",
        forces[0].1
    );
    // lifted 1 mm clear of the top: no contact
    let clear = Ellipsoid {
        centre: [centre[0], centre[1], centre[2] + depth + 1e-3],
        ..e
    };
    let mut n = 0;
    t.touches(&clear, |_| n += 1);
    assert_eq!(n, 0);
}

mbs::multibody! {
    /// An egg on six coordinates, its contact ellipsoid off its centre of mass, against the
    /// plane z = floor.
    pub model Egg {
        param floor = 0.0;
        dof x = 0.0; dof y = 0.0; dof z = 0.1; dof a = 0.0; dof b = 0.3; dof r = 0.2;
        body egg { mass = 0.1; inertia = (4e-5, 5e-5, 6e-5); }
        TOG[egg] = Tdisp(x, y, z) * Trotz(a) * Troty(b) * Trotx(r);
        point tip on egg at (0.01, -0.005, 0.004);
        gravity(0, 0, -9.81);
        contact(tip, ellipsoid = (0.03, 0.02, 0.025), plane = z, offset = floor, k = 2e6, exponent = 1.5, dissipation = 1.0, mu = 0.6, eps = 0.01);
    }
}

mbs::multibody! {
    /// The egg without its contact.
    pub model EggAloft {
        dof x = 0.0; dof y = 0.0; dof z = 0.1; dof a = 0.0; dof b = 0.3; dof r = 0.2;
        body egg { mass = 0.1; inertia = (4e-5, 5e-5, 6e-5); }
        TOG[egg] = Tdisp(x, y, z) * Trotz(a) * Troty(b) * Trotx(r);
        point tip on egg at (0.01, -0.005, 0.004);
        gravity(0, 0, -9.81);
    }
}

/// The egg's ellipsoid on a terrain.
#[derive(Clone)]
struct EggOn {
    terrain: Terrain,
    frame: usize,
    point: usize,
}

impl Efforts for EggOn {
    fn efforts(&mut self, e: &mut mbs::Effort) -> Result<(), String> {
        self.terrain
            .apply_ellipsoid(e, self.frame, self.point, [0.03, 0.02, 0.025]);
        Ok(())
    }
}

/// The generalised forces of the generated contact against those of the same ellipsoid on
/// `terrain`, at states pressed `floor` + up to 4 mm into it, turning and sliding.
fn egg_agrees(floor: f64, terrain: Terrain) {
    let mut generated = Egg::default();
    let mut p = generated.params().clone();
    p.floor = floor;
    generated.set_params(p).unwrap();
    let aloft = EggAloft::default();
    let info = aloft.info();
    let on = WithEfforts::new(
        EggAloft::default(),
        EggOn {
            terrain,
            frame: info.frame_index("egg").unwrap(),
            point: info.point_index("tip").unwrap(),
        },
    );
    let n = Egg::NQ;
    let mut kin = Kinematics::new::<EggAloft>();
    let mut touched = 0;
    for k in 0..40 {
        let u = |j: usize| ((k * 7 + j * 13) as f64 * 0.61803).fract() - 0.5;
        let mut q: Vec<f64> = (0..n).map(|j| 2.0 * u(j)).collect();
        let qd: Vec<f64> = (0..n).map(|j| 0.8 * u(j + 6)).collect();
        // put the lowest point of the ellipsoid 0–4 mm below the floor
        q[2] = 0.0;
        aloft.kinematics(0.0, &q, &qd, &mut kin);
        let f = &kin.frames[info.frame_index("egg").unwrap()];
        let e = Ellipsoid {
            centre: kin.points[info.point_index("tip").unwrap()].position,
            rotation: &f.pose.rotation,
            axes: [0.03, 0.02, 0.025],
        };
        let low = e.support([0.0, 0.0, 1.0])[2];
        q[2] = floor - low - 0.004 * (u(12) + 0.5);
        let mut m = vec![0.0; n * n];
        let (mut h0, mut h1, mut h2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        aloft.dynamics(0.0, &q, &qd, &[], &mut m, &mut h0);
        generated.dynamics(0.0, &q, &qd, &[], &mut m, &mut h1);
        on.dynamics(0.0, &q, &qd, &[], &mut m, &mut h2);
        let scale = (0..n).map(|i| (h1[i] - h0[i]).abs()).fold(0.0, f64::max);
        if scale > 0.0 {
            touched += 1;
        }
        for i in 0..n {
            assert!(
                (h1[i] - h2[i]).abs() <= 1e-12 * scale.max(1.0),
                "floor {floor}, state {k}, coordinate {i}: generated {} terrain {}",
                h1[i],
                h2[i]
            );
        }
    }
    assert!(touched >= 35, "{touched} of 40 states in contact");
}

#[test]
fn an_ellipsoid_on_the_terrain_is_the_generated_contact() {
    let law = ContactLaw {
        k: 2e6,
        c: 0.0,
        exponent: 1.5,
        dissipation: 1.0,
        mu: 0.6,
        eps: 0.01,
    };
    // the ground
    egg_agrees(
        0.0,
        Terrain {
            law,
            ..Terrain::default()
        },
    );
    // a box's top (a box far wider than the egg), the ground left out
    egg_agrees(
        0.1,
        Terrain {
            ground: false,
            blocks: vec![Block {
                min: [-10.0, -10.0],
                max: [10.0, 10.0],
                height: 0.1,
            }],
            law,
            ..Terrain::default()
        },
    );
}

#[test]
fn the_model_stands_on_a_platform() {
    let model = Human::default();
    let n = Human::NQ;
    let reference = GaitReference::still(model.info(), 0.1).unwrap();
    let (mut q0, qd0) = cycle_start(&model, &reference);
    // a platform 10 cm high under both feet, the body raised by as much
    let height = 0.1;
    q0[1] += height;
    let platform = Block {
        min: [-0.5, -0.5],
        max: [0.5, 0.5],
        height,
    };
    let tracking = Tracking::new(reference.clone(), model.info(), 3000.0, 30.0).unwrap();
    let feet = OnTerrain::new(&model, tracking, vec![platform]);
    let on = feet.clone();
    let options = Options {
        q0: Some(q0.clone()),
        qd0: Some(qd0),
        output: Output::Every { dt: 0.01 },
        ..Options::adaptive(3.0, 1e-5)
    };
    let options_sunk = options.clone();
    let (tr, stats) = mbs::simulate(
        WithEfforts::new(model.clone(), feet),
        Scheme::Radau5,
        options.clone(),
    )
    .expect("standing on the platform is a regular run");
    // the same stance on the ground (the generated contacts), 10 cm lower
    let mut q_ground = q0.clone();
    q_ground[1] -= height;
    let tracking = Tracking::new(reference.clone(), model.info(), 3000.0, 30.0).unwrap();
    let (flat, _) = mbs::simulate(
        WithEfforts::new(model.clone(), tracking),
        Scheme::Radau5,
        Options {
            q0: Some(q_ground),
            ..options
        },
    )
    .expect("standing on the ground is a regular run");
    let last = tr.len() - 1;
    let (ql, qdl) = (&tr.q(last)[..n], &tr.qd(last)[..n]);
    let mut kin = Kinematics::new::<Human>();
    model.kinematics(tr.t[last], ql, qdl, &mut kin);
    let f = on.forces(&kin);
    let weight = MASS * G;
    let shares = [f[0][1] / weight, f[1][1] / weight].map(|s| format!("{s:.4}"));
    assert_eq!(
        shares[0], shares[1],
        "the documents say each foot carries as much"
    );
    quoted::says(
        "docs/human_gait.md",
        &[format!(
            "it stands the same way on a 10 cm platform: the platform carries {} of the weight on each foot",
            shares[0]
        )],
    );
    println!(
        "standing 3 s on a {height} m platform, radau5 rtol 1e-5: {} steps; pelvis moved \
         ({:+.2e}, {:+.2e}, {:+.2e}) m; the platform carries {:.4} and {:.4} of the weight",
        stats.steps,
        ql[0] - q0[0],
        ql[1] - q0[1],
        ql[2] - q0[2],
        f[0][1] / weight,
        f[1][1] / weight
    );
    assert!(((f[0][1] + f[1][1]) / weight - 1.0).abs() < 0.01);
    assert!((f[0][1] / weight - 0.5).abs() < 0.05 && (f[1][1] / weight - 0.5).abs() < 0.05);
    // the stance on the ground (whose pelvis stays within a centimetre, `human_model`), raised by the platform's height, at every output instant
    let mut apart = 0.0f64;
    for (i, &t) in tr.t.iter().enumerate() {
        let j = flat
            .t
            .iter()
            .position(|&u| u == t)
            .expect("the same output instants");
        for c in 0..n {
            let shift = if c == 1 { height } else { 0.0 };
            apart = apart.max((tr.q(i)[c] - flat.q(j)[c] - shift).abs());
        }
    }
    println!("largest difference to the stance on the ground, raised: {apart:.2e}");
    assert!(apart < 1e-8, "{apart}");
    // started 3 cm into the platform: a typed failure naming the ellipsoid
    let mut sunk = q0.clone();
    sunk[1] -= 0.03;
    let tracking = Tracking::new(reference, model.info(), 3000.0, 30.0).unwrap();
    let e = mbs::simulate(
        WithEfforts::new(
            model.clone(),
            OnTerrain::new(&model, tracking, vec![platform]),
        ),
        Scheme::Radau5,
        Options {
            q0: Some(sunk),
            ..options_sunk
        },
    )
    .expect_err("a foot through the platform stops the run");
    println!("{e}");
    assert!(matches!(e.kind, mbs::Failure::EffortRejected { .. }), "{e}");
    assert!(e.to_string().contains("passed through the box"), "{e}");
    // every foot ellipsoid that touches, touches the platform's top
    let sp = support_points(&model, &kin);
    for foot in &sp {
        for (x, _) in foot {
            assert!(
                x[1] > height - 0.01,
                "an ellipsoid below the platform's top: {x:?}"
            );
        }
    }
}

/// Ellipsoids tilted at random and pressed at random into a box's upper corner, up to a few
/// centimetres deep: the terrain's way out is the largest separation of the box's and the
/// ellipsoid's support functions over the unit sphere (sampled on 200 × 400 directions, then
/// refined), to 1e-9 m, and its depth is that separation along its own normal. Before, 23 of
/// these 600 took a deeper way, up to 18.7 mm deeper: an edge skipped because the ellipsoid
/// lay within the plane of one of its faces (it may still leave by the edge's way, when its
/// deepest point behind the other face is near the edge), and a corner searched at the
/// sphere's largest separation alone, which lay outside the corner's cone.
#[test]
fn ellipsoids_pressed_into_a_corner_leave_by_the_shortest_way() {
    let t = tall_box();
    let (c, h) = ([0.5, 0.3, 0.15], [0.5, 0.3, 0.15]);
    let mut seed = 12345u64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut touching, mut worst) = (0, 0.0f64);
    for case in 0..600 {
        let (a, b, g) = (6.3 * rnd(), 3.1 * rnd() - 1.55, 6.3 * rnd());
        let r = matmul(matmul(rz(a), ry(b)), rx(g));
        let axes = [
            0.03 + 0.15 * rnd(),
            0.005 + 0.04 * rnd(),
            0.005 + 0.04 * rnd(),
        ];
        let x = [
            0.96 + 0.08 * rnd(),
            0.56 + 0.08 * rnd(),
            0.28 + 0.06 * rnd(),
        ];
        let sep = |n: [f64; 3]| separation((c, h), (x, &r, axes), n);
        let (best, _) = largest_separation(sep, (200, 400), 1e-10);
        let e = Ellipsoid {
            centre: x,
            rotation: &r,
            axes,
        };
        let mut touches = Vec::new();
        t.touches(&e, |x| touches.push(x));
        if best.abs() < 1e-7 {
            continue;
        }
        assert_eq!(
            touches.len(),
            usize::from(best < 0.0),
            "case {case}: {best}"
        );
        if let Some(got) = touches.first() {
            touching += 1;
            // no deeper than the shortest way (the sampled search may fall short of the
            // terrain's by its refinement: 5e-8 at most here, at the top's normal)
            assert!(
                got.depth <= -best + 1e-9 && got.depth >= -best - 1e-7,
                "case {case}: depth {} where the shortest way out is {}",
                got.depth,
                -best
            );
            assert!((sep(got.normal) + got.depth).abs() < 1e-12, "case {case}");
            worst = worst.max((got.depth + best).abs());
        }
    }
    println!("{touching} of 600 touching; depths within {worst:.1e} m of the sampled search's");
    quoted::says(
        "docs/status.md",
        &[format!(
            "leave by the shortest way to within {worst:.1e} m of the sampled search"
        )],
    );
    assert!(touching > 300);
}

/// The separation s(n) = n·(x − c) − Σ hᵢ|nᵢ| − √(nᵀ R D² Rᵀ n) of the box (centre c,
/// half-sizes h) and the ellipsoid (centre x, axes R, semi-axes D) along the unit n.
fn separation(
    (c, h): ([f64; 3], [f64; 3]),
    (x, r, axes): ([f64; 3], &[[f64; 3]; 3], [f64; 3]),
    n: [f64; 3],
) -> f64 {
    let m = [0, 1, 2].map(|k| (0..3).map(|i| r[i][k] * n[i]).sum::<f64>());
    let support = (0..3).map(|k| (axes[k] * m[k]).powi(2)).sum::<f64>().sqrt();
    (0..3)
        .map(|i| n[i] * (x[i] - c[i]) - h[i] * n[i].abs())
        .sum::<f64>()
        - support
}

/// The largest of `sep` over the unit sphere and its direction: sampled on `m` × `k`
/// directions (polar angle × azimuth), then refined by coordinate steps halving down to
/// `finest` rad.
fn largest_separation(
    sep: impl Fn([f64; 3]) -> f64,
    (m, k): (usize, usize),
    finest: f64,
) -> (f64, [f64; 3]) {
    let pi = std::f64::consts::PI;
    let dir = |th: f64, ph: f64| [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
    let (mut best, mut arg) = (f64::NEG_INFINITY, (0.0, 0.0));
    for a in 0..=m {
        for b in 0..k {
            let (th, ph) = (pi * a as f64 / m as f64, 2.0 * pi * b as f64 / k as f64);
            let s = sep(dir(th, ph));
            if s > best {
                (best, arg) = (s, (th, ph));
            }
        }
    }
    let mut step = pi / m as f64;
    while step > finest {
        let mut moved = false;
        for (dt, dp) in [(step, 0.0), (-step, 0.0), (0.0, step), (0.0, -step)] {
            let s = sep(dir(arg.0 + dt, arg.1 + dp));
            if s > best {
                (best, arg, moved) = (s, (arg.0 + dt, arg.1 + dp), true);
            }
        }
        if !moved {
            step *= 0.5;
        }
    }
    (best, dir(arg.0, arg.1))
}

/// A box alone (no ground), 1 × 0.6 m and 0.3 m high, from the origin.
fn tall_box() -> Terrain {
    Terrain {
        blocks: vec![Block {
            min: [0.0, 0.0],
            max: [1.0, 0.6],
            height: 0.3,
        }],
        ground: false,
        ..Terrain::default()
    }
}

fn matmul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn rz(a: f64) -> [[f64; 3]; 3] {
    let (s, c) = a.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

fn ry(a: f64) -> [[f64; 3]; 3] {
    let (s, c) = a.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}
