//! The shapes a model is drawn with (`ModelInfo::shapes`): the declared ones, then for each
//! body that declares none its equivalent box, computed here from its mass and inertia with
//! the default parameters.

use crate::expr::SliceEnv;
use crate::expr::emit::literal as number;
use crate::mech::system::{Geometry, IDENTITY, ShapeDef, System};

/// Thinnest side of a default box, relative to its longest: a slender body is drawn as a bar
/// of this thickness, a flat one as a plate.
pub const MIN_ASPECT: f64 = 0.04;

/// Density of the sphere that stands for a point mass (water, kg/m³).
pub const POINT_MASS_DENSITY: f64 = 1000.0;

/// Declared shapes, then one default per body without any.
pub fn shapes(sys: &System) -> Vec<ShapeDef> {
    let mut out = sys.shapes.clone();
    let defaults = sys.param_defaults();
    let env = SliceEnv {
        params: &defaults,
        ..SliceEnv::default()
    };
    for (i, f) in sys.frames.iter().enumerate() {
        let Some(inr) = f.inertia else { continue };
        if sys.shapes.iter().any(|s| s.frame == Some(i)) {
            continue;
        }
        let mut roots = vec![inr.mass];
        roots.extend(inr.tensor);
        let v = sys.arena.eval(&roots, &env);
        let tensor = [v[1], v[2], v[3], v[4], v[5], v[6]];
        if let Some(s) = default_shape(i, v[0], tensor) {
            out.push(s);
        }
    }
    out
}

/// The default shape of body `frame` of mass `m` and inertia tensor (xx, yy, zz, xy, xz, yz)
/// about G: the box of the same mass and principal moments, along the principal axes
/// (sides at least [`MIN_ASPECT`] of the longest), or a sphere of water's density for a
/// point mass.
pub fn default_shape(frame: usize, m: f64, tensor: [f64; 6]) -> Option<ShapeDef> {
    if m.is_nan() || m <= 0.0 || !m.is_finite() || tensor.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let (moments, axes) = crate::dsl::inertia::principal_axes(tensor);
    // a box a × b × c has I_x = m (b² + c²) / 12: a² = 6 (I_y + I_z − I_x) / m
    let side = |i: usize| {
        let (a, b, c) = (moments[i], moments[(i + 1) % 3], moments[(i + 2) % 3]);
        (6.0 * (b + c - a) / m).max(0.0).sqrt()
    };
    let mut size = [side(0), side(1), side(2)];
    let longest = size[0].max(size[1]).max(size[2]);
    let shape = |geometry, rotation| ShapeDef {
        frame: Some(frame),
        geometry,
        at: [0.0; 3],
        rotation,
        color: None,
        declared: false,
    };
    // a point mass (or nearly): a sphere of water's density (the cube roots apart, so that a
    // mass near f64::MAX gives a radius rather than overflow to ∞)
    let radius = m.cbrt() * (3.0 / (4.0 * std::f64::consts::PI * POINT_MASS_DENSITY)).cbrt();
    if longest < 1e-3 * radius {
        return radius
            .is_finite()
            .then(|| shape(Geometry::Sphere(radius), IDENTITY));
    }
    for s in &mut size {
        *s = s.max(MIN_ASPECT * longest);
    }
    // a size that overflowed (moments near f64::MAX over a small mass): no shape to draw
    size.iter()
        .all(|x| x.is_finite())
        .then(|| shape(Geometry::Box(size), axes))
}

/// `&[::mbs::ShapeInfo { … }, …]`, the Rust text of the list.
pub fn literal(shapes: &[ShapeDef]) -> String {
    let v3 = |v: [f64; 3]| format!("[{}, {}, {}]", number(v[0]), number(v[1]), number(v[2]));
    let items: Vec<String> = shapes
        .iter()
        .map(|s| {
            let kind = match s.geometry {
                Geometry::Box(size) => format!("Box {{ size: {} }}", v3(size)),
                Geometry::Cylinder(r, l, axis) => {
                    format!(
                        "Cylinder {{ radius: {}, length: {}, axis: {axis} }}",
                        number(r),
                        number(l)
                    )
                }
                Geometry::Sphere(r) => format!("Sphere {{ radius: {} }}", number(r)),
                Geometry::Line(a, b) => format!("Line {{ from: {}, to: {} }}", v3(a), v3(b)),
            };
            format!(
                "::mbs::ShapeInfo {{ frame: {}, kind: ::mbs::ShapeKind::{kind}, at: {}, rotation: [{}, {}, {}], color: {}, declared: {} }}",
                match s.frame {
                    Some(i) => format!("::core::option::Option::Some({i})"),
                    None => "::core::option::Option::None".to_string(),
                },
                v3(s.at),
                v3(s.rotation[0]),
                v3(s.rotation[1]),
                v3(s.rotation[2]),
                match s.color {
                    Some([r, g, b]) => format!("::core::option::Option::Some([{r}, {g}, {b}])"),
                    None => "::core::option::Option::None".to_string(),
                },
                s.declared
            )
        })
        .collect();
    format!("&[{}]", items.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry(m: f64, t: [f64; 6]) -> (Geometry, [[f64; 3]; 3]) {
        let s = default_shape(0, m, t).unwrap();
        (s.geometry, s.rotation)
    }

    #[test]
    fn a_mass_near_the_largest_number_is_drawn_finite_or_not_at_all() {
        let (Geometry::Sphere(r), _) = geometry(1e308, [0.0; 6]) else {
            panic!()
        };
        assert!(r.is_finite() && r > 0.0, "{r}");
        // moments near f64::MAX over a small mass: sides that overflow, no shape
        assert!(default_shape(0, 1e-300, [1e308, 1e308, 1e308, 0.0, 0.0, 0.0]).is_none());
        let text = literal(&[default_shape(0, 1e308, [0.0; 6]).unwrap()]);
        assert!(!text.contains("inf") && !text.contains("NaN"), "{text}");
    }

    #[test]
    fn a_box_gives_back_its_sides() {
        let (m, a, b, c) = (2.0, 0.3, 0.5, 0.7);
        let t = [
            m * (b * b + c * c) / 12.0,
            m * (a * a + c * c) / 12.0,
            m * (a * a + b * b) / 12.0,
            0.0,
            0.0,
            0.0,
        ];
        let (Geometry::Box(size), r) = geometry(m, t) else {
            panic!()
        };
        for (s, e) in size.iter().zip([a, b, c]) {
            assert!((s - e).abs() < 1e-12, "{size:?}");
        }
        assert_eq!(r, IDENTITY);
    }

    #[test]
    fn a_bar_is_slender_and_a_point_mass_a_sphere() {
        let (m, l) = (1.0, 1.0);
        let (Geometry::Box(size), _) =
            geometry(m, [m * l * l / 12.0, 0.0, m * l * l / 12.0, 0.0, 0.0, 0.0])
        else {
            panic!()
        };
        assert!((size[1] - l).abs() < 1e-12);
        assert_eq!(size[0], MIN_ASPECT * l);
        assert_eq!(size[2], MIN_ASPECT * l);
        let (Geometry::Sphere(r), _) =
            geometry(1000.0 * 4.0 / 3.0 * std::f64::consts::PI, [0.0; 6])
        else {
            panic!()
        };
        assert!((r - 1.0).abs() < 1e-12);
    }

    #[test]
    fn products_of_inertia_turn_the_box_onto_the_principal_axes() {
        // a box 0.2 × 1 × 0.2 turned by 30° about z
        let (m, a, b, c) = (1.0, 0.2, 1.0, 0.2);
        let p = [
            m * (b * b + c * c) / 12.0,
            m * (a * a + c * c) / 12.0,
            m * (a * a + b * b) / 12.0,
        ];
        let (s, co) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
        let r = [[co, -s, 0.0], [s, co, 0.0], [0.0, 0.0, 1.0]];
        // I = R diag(p) Rᵀ
        let i = |x: usize, y: usize| (0..3).map(|k| r[x][k] * p[k] * r[y][k]).sum::<f64>();
        let t = [i(0, 0), i(1, 1), i(2, 2), i(0, 1), i(0, 2), i(1, 2)];
        let (Geometry::Box(size), axes) = geometry(m, t) else {
            panic!()
        };
        // the long side's axis is the body's direction (∓sin 30°, cos 30°, 0)
        let long = (0..3).max_by(|&x, &y| size[x].total_cmp(&size[y])).unwrap();
        assert!((size[long] - b).abs() < 1e-9, "{size:?}");
        let dir = [axes[0][long], axes[1][long], axes[2][long]];
        assert!((dir[0] * -s + dir[1] * co).abs() > 1.0 - 1e-9, "{dir:?}");
        let det = axes[0][0] * (axes[1][1] * axes[2][2] - axes[1][2] * axes[2][1])
            - axes[0][1] * (axes[1][0] * axes[2][2] - axes[1][2] * axes[2][0])
            + axes[0][2] * (axes[1][0] * axes[2][1] - axes[1][1] * axes[2][0]);
        assert!((det - 1.0).abs() < 1e-12);
    }
}
