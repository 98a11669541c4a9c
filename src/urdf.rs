//! URDF robot descriptions as `multibody!` source: `mbs import urdf FILE.urdf > model.rs`
//! (feature `urdf`). The text is a starting point the user edits (effects, scenes, shapes).
//!
//! What a URDF says and what the importer writes:
//!
//! - a link frame is at its parent joint; a body's frame (TOG) is at its centre of mass, so a
//!   body is its link frame moved by `<inertial><origin xyz>`, axes parallel to the link
//!   frame; an `<inertial><origin rpy>` rotates the inertia tensor into those axes; when
//!   other links hang from a link with its centre of mass off the joint, its link frame is a
//!   `frame {link}_frame` the body and the children share (cheaper than going back from G);
//! - a joint is `Tdisp(xyz) * Trotz(yaw) * Troty(pitch) * Trotx(roll)` (URDF's fixed-axis
//!   roll–pitch–yaw, R = Rz·Ry·Rx) then its motion: `Trotx/y/z(q)` about a coordinate axis,
//!   `Trotn(nx, ny, nz, q)` about another, `Tdisp` along the axis for a prismatic joint;
//! - `fixed` joints merge the child's mass and inertia into its parent (a massless child
//!   stays a `frame`), and the merged joint's origin stays numbers (the merged mass was
//!   computed with it); `floating` is `Tfree`: three translations and the Euler angles z, y, x
//!   in a chart the runtime re-centres before gimbal lock; `planar`
//!   two translations in the plane and a rotation about its normal; a `mimic` joint follows
//!   its leader (`multiplier * leader + offset`) without a coordinate of its own;
//! - the root link is the ground (or, with [`ImportOptions::floating_base`], a body on a
//!   floating joint); `gravity(0, 0, -g)` (z up, as in ROS);
//! - a joint's `<dynamics damping friction>` is a `generalized_force` on its coordinate in
//!   the effects `joint_damping` (−c q̇) and `joint_friction` (−f tanh(q̇ / eps), Coulomb
//!   friction regularised below `joint_friction_eps` = 0.01 rad/s or m/s); a mimic joint's
//!   acts on its leader, times the multiplier;
//! - box, cylinder and sphere visuals become `shape` statements; meshes a comment.
//!
//! Masses, centres of mass, inertias and joint offsets (`{joint}_dx`, …) are parameters; angles
//! are numbers.

use roxmltree::{Document, Node};
use std::collections::{HashMap, HashSet};
use std::fmt::Write as _;
use std::path::Path;

// the edit distance of `multibody!`'s suggestions, shared as `op_count.rs` is
#[path = "../mbs-symbolic/src/dsl/edit_distance.rs"]
mod edit_distance;

/// What is wrong with a URDF description. Each message names the link or joint and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UrdfError {
    /// The file could not be read.
    #[error("cannot read {path}: {message}")]
    Io { path: String, message: String },
    /// The text is not well-formed XML.
    #[error("not well-formed XML: {message}")]
    Xml { message: String },
    /// The root element is not `<robot>`.
    #[error("the root element is `<{found}>`; a URDF file holds one `<robot name=\"…\">`")]
    NotRobot { found: String },
    /// A required element or attribute is missing.
    #[error("line {line}: {what} is missing {missing}; add it")]
    Missing {
        line: u32,
        what: String,
        missing: String,
    },
    /// An attribute does not hold the numbers it should.
    #[error("line {line}: {what} is `{value}`, expected {expected}")]
    BadValue {
        line: u32,
        what: String,
        value: String,
        expected: String,
    },
    /// Two links or two joints have the same name.
    #[error("line {line}: there are two {kind}s named `{name}`; rename one")]
    Duplicate {
        line: u32,
        kind: &'static str,
        name: String,
    },
    /// A joint names a link that does not exist.
    #[error("joint `{joint}`: its {role} link `{link}` is not a `<link>` of the robot{hint}")]
    UnknownLink {
        joint: String,
        role: &'static str,
        link: String,
        hint: String,
    },
    /// A link is the child of two joints.
    #[error(
        "link `{link}` is the child of two joints, `{first}` and `{second}`: a URDF is a tree; \
         close a loop with a `constraint` in the imported model instead"
    )]
    TwoParents {
        link: String,
        first: String,
        second: String,
    },
    /// The joints form a cycle.
    #[error(
        "the joints form a cycle through the links {}: a URDF is a tree; remove one joint of \
         the cycle (and close the loop with a `constraint` in the imported model)",
        .links.iter().map(|l| format!("`{l}`")).collect::<Vec<_>>().join(", ")
    )]
    Cycle { links: Vec<String> },
    /// No link, or several links, without a parent joint.
    #[error(
        "the robot has {} root links ({}): exactly one link may be without a parent joint; \
         attach the others with joints",
        .roots.len(),
        .roots.iter().map(|l| format!("`{l}`")).collect::<Vec<_>>().join(", ")
    )]
    Roots { roots: Vec<String> },
    /// The robot has no link.
    #[error("the robot has no `<link>`")]
    NoLinks,
    /// A negative mass.
    #[error("link `{link}`: its mass is {mass}; a mass is positive (or 0 for a massless link)")]
    NegativeMass { link: String, mass: f64 },
    /// An inertia tensor no rigid body has: a negative principal moment (the tensor is not
    /// positive semi-definite), or principal moments that violate the triangle inequality.
    /// Checked for what moves: a body's tensor about its centre of mass in its link axes,
    /// links fixed to it included (the ground's links are not checked).
    #[error(
        "link `{link}`{}: its inertia about the centre of mass in the link axes (ixx {ixx}, iyy \
         {iyy}, izz {izz}, ixy {ixy}, ixz {ixz}, iyz {iyz}) is not a rigid body's: {problem}; \
         correct the `<inertia>` (about the centre of mass in the `<inertial><origin>` axes, \
         ixy = −∫xy dm)",
        if .merged.is_empty() { String::new() } else {
            format!(" (with {}, fixed to it)", .merged.iter().map(|m| format!("`{m}`")).collect::<Vec<_>>().join(", "))
        }
    )]
    Inertia {
        link: String,
        /// the links fixed to it, whose inertias are included
        merged: Vec<String>,
        ixx: f64,
        iyy: f64,
        izz: f64,
        ixy: f64,
        ixz: f64,
        iyz: f64,
        /// what is wrong, as `multibody!` says it (`mbs::inertia::inertia_problem`)
        problem: String,
    },
    /// A joint type the importer does not know.
    #[error(
        "joint `{joint}`: type `{kind}` is not supported; use revolute, continuous, prismatic, \
         fixed, floating or planar"
    )]
    UnsupportedJoint { joint: String, kind: String },
    /// A joint axis of zero length.
    #[error("joint `{joint}`: its axis ({x}, {y}, {z}) has zero length; give a direction")]
    ZeroAxis {
        joint: String,
        x: f64,
        y: f64,
        z: f64,
    },
    /// A `mimic` the importer cannot follow.
    #[error("joint `{joint}`: it mimics `{leader}`, {problem}")]
    Mimic {
        joint: String,
        leader: String,
        problem: String,
    },
    /// No joint moves: there is nothing to simulate.
    #[error(
        "the robot has no joint that moves (every joint is fixed, or there is none): give it a \
         revolute, continuous, prismatic, floating or planar joint, or free its root link \
         (`--floating-base`, `ImportOptions::floating_base`)"
    )]
    NoMotion,
    /// A joint that moves no mass: the mass matrix would be singular.
    #[error(
        "joint `{joint}` moves no link with mass (link `{link}` and the links after it have no \
         `<inertial>` with a positive mass), so the mass matrix would be singular; give one of \
         them an `<inertial>` or make the joint `fixed`"
    )]
    Massless { joint: String, link: String },
}

/// An imported robot: the model's name and its `multibody!` text.
#[derive(Debug, Clone)]
pub struct Imported {
    /// the model's name (`model NAME`), from `<robot name>` in CamelCase
    pub name: String,
    /// the `model NAME { … }` item, indented for a `multibody!` block
    pub model: String,
}

impl Imported {
    /// The model in a `mbs::multibody! { … }` block, with a header naming its source.
    pub fn block(&self, source: &str) -> String {
        format!(
            "// Imported from {source} by `mbs import urdf`: a starting point to edit (effects,\n\
             // scenes, shapes). Link frames are at the joints; a body's frame is at its centre of\n\
             // mass, axes parallel to its link frame.\nmbs::multibody! {{\n{}}}\n",
            self.model
        )
    }
}

/// How a robot is imported.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ImportOptions {
    /// Free the root link: a `floating` joint `floating_base` from the ground to it (a drone, a
    /// legged robot), instead of fixing it to the ground.
    pub floating_base: bool,
}

/// Reads a URDF file and imports it ([`import_with`]).
pub fn import_file(path: &Path, options: ImportOptions) -> Result<Imported, UrdfError> {
    let text = std::fs::read_to_string(path).map_err(|e| UrdfError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    import_with(&text, options)
}

/// Imports the URDF text `urdf` as a `multibody!` model, its root link fixed to the ground.
pub fn import(urdf: &str) -> Result<Imported, UrdfError> {
    import_with(urdf, ImportOptions::default())
}

/// Imports the URDF text `urdf` as a `multibody!` model.
pub fn import_with(urdf: &str, options: ImportOptions) -> Result<Imported, UrdfError> {
    let doc = Document::parse(urdf).map_err(|e| UrdfError::Xml {
        message: e.to_string(),
    })?;
    let mut robot = read_robot(&doc)?;
    // the root, if there is exactly one (otherwise the tree's check says what is wrong)
    let children: HashSet<&str> = robot.joints.iter().map(|j| j.child.as_str()).collect();
    let roots: Vec<usize> = (0..robot.links.len())
        .filter(|&i| !children.contains(robot.links[i].name.as_str()))
        .collect();
    if let (true, &[root]) = (options.floating_base, roots.as_slice()) {
        let fresh = |wanted: &str, taken: &dyn Fn(&str) -> bool| {
            let mut name = wanted.to_string();
            let mut k = 2;
            while taken(&name) {
                name = format!("{wanted}_{k}");
                k += 1;
            }
            name
        };
        let world = fresh("world", &|n| robot.links.iter().any(|l| l.name == n));
        let joint = fresh("floating_base", &|n| {
            robot.joints.iter().any(|j| j.name == n)
        });
        robot.joints.insert(
            0,
            Joint {
                name: joint,
                kind: JointKind::Floating,
                parent: world.clone(),
                child: robot.links[root].name.clone(),
                origin: Origin::default(),
                axis: [1.0, 0.0, 0.0],
                limit: None,
                mimic: None,
                damping: 0.0,
                friction: 0.0,
            },
        );
        robot.links.push(Link {
            name: world,
            inertial: None,
            visuals: Vec::new(),
        });
    }
    let tree = Tree::new(&robot)?;
    Writer::new(&robot, &tree).write()
}

// ---------------------------------------------------------------------------------------------
// Small linear algebra

type V3 = [f64; 3];
type M3 = [[f64; 3]; 3];

const I3: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn mul(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for (i, row) in c.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn transpose(a: &M3) -> M3 {
    let mut t = [[0.0; 3]; 3];
    for (i, row) in a.iter().enumerate() {
        for (j, x) in row.iter().enumerate() {
            t[j][i] = *x;
        }
    }
    t
}

fn apply(a: &M3, v: V3) -> V3 {
    [0, 1, 2].map(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: V3, s: f64) -> V3 {
    a.map(|x| x * s)
}

/// URDF's rpy: R = Rz(yaw)·Ry(pitch)·Rx(roll).
fn rpy_matrix(rpy: V3) -> M3 {
    let (sr, cr) = rpy[0].sin_cos();
    let (sp, cp) = rpy[1].sin_cos();
    let (sy, cy) = rpy[2].sin_cos();
    let rx = [[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]];
    let ry = [[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]];
    let rz = [[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]];
    mul(&rz, &mul(&ry, &rx))
}

/// A rigid transform: x ↦ r·x + p.
#[derive(Clone, Copy, Debug)]
struct Rigid {
    r: M3,
    p: V3,
}

impl Rigid {
    const IDENTITY: Rigid = Rigid { r: I3, p: [0.0; 3] };

    fn of(o: &Origin) -> Rigid {
        Rigid {
            r: rpy_matrix(o.rpy),
            p: o.xyz,
        }
    }

    fn then(&self, b: &Rigid) -> Rigid {
        Rigid {
            r: mul(&self.r, &b.r),
            p: add(self.p, apply(&self.r, b.p)),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Reading the XML

#[derive(Clone, Copy, Debug, Default)]
struct Origin {
    xyz: V3,
    rpy: V3,
}

#[derive(Clone, Debug)]
struct Inertial {
    origin: Origin,
    mass: f64,
    /// ixx, iyy, izz, ixy, ixz, iyz
    inertia: [f64; 6],
}

#[derive(Clone, Debug)]
enum Geometry {
    Box(V3),
    Cylinder { radius: f64, length: f64 },
    Sphere(f64),
    Mesh(String),
}

#[derive(Clone, Debug)]
struct Visual {
    origin: Origin,
    geometry: Geometry,
    color: Option<[u8; 3]>,
}

#[derive(Clone, Debug)]
struct Link {
    name: String,
    inertial: Option<Inertial>,
    visuals: Vec<Visual>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum JointKind {
    Revolute,
    Continuous,
    Prismatic,
    Fixed,
    Floating,
    Planar,
}

#[derive(Clone, Debug)]
struct Mimic {
    leader: String,
    multiplier: f64,
    offset: f64,
}

#[derive(Clone, Debug)]
struct Joint {
    name: String,
    kind: JointKind,
    parent: String,
    child: String,
    origin: Origin,
    axis: V3,
    /// lower, upper, effort, velocity (as given)
    limit: Option<[Option<f64>; 4]>,
    mimic: Option<Mimic>,
    /// `<dynamics damping friction>` (each 0 when not given)
    damping: f64,
    friction: f64,
}

struct Robot {
    name: String,
    links: Vec<Link>,
    joints: Vec<Joint>,
}

fn line(doc: &Document, n: Node) -> u32 {
    doc.text_pos_at(n.range().start).row
}

fn describe(n: Node) -> String {
    match n.attribute("name") {
        Some(name) => format!("`<{} name=\"{name}\">`", n.tag_name().name()),
        None => format!("`<{}>`", n.tag_name().name()),
    }
}

fn child<'a, 'i>(n: Node<'a, 'i>, tag: &str) -> Option<Node<'a, 'i>> {
    n.children()
        .find(|c| c.is_element() && c.tag_name().name() == tag)
}

fn attr<'a>(doc: &Document, n: Node<'a, '_>, name: &str) -> Result<&'a str, UrdfError> {
    n.attribute(name).ok_or_else(|| UrdfError::Missing {
        line: line(doc, n),
        what: describe(n),
        missing: format!("the attribute `{name}`"),
    })
}

fn numbers<const N: usize>(
    doc: &Document,
    n: Node,
    name: &str,
    s: &str,
) -> Result<[f64; N], UrdfError> {
    let bad = || UrdfError::BadValue {
        line: line(doc, n),
        what: format!("`{name}` of {}", describe(n)),
        value: s.to_string(),
        expected: if N == 1 {
            "a finite number".to_string()
        } else {
            format!("{N} finite numbers separated by spaces")
        },
    };
    let v: Vec<f64> = s
        .split_whitespace()
        .map(|x| x.parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(bad)?;
    v.try_into().map_err(|_| bad())
}

fn number_attr<const N: usize>(doc: &Document, n: Node, name: &str) -> Result<[f64; N], UrdfError> {
    numbers(doc, n, name, attr(doc, n, name)?)
}

fn optional_number(doc: &Document, n: Node, name: &str) -> Result<Option<f64>, UrdfError> {
    n.attribute(name)
        .map(|s| numbers::<1>(doc, n, name, s).map(|[x]| x))
        .transpose()
}

fn origin(doc: &Document, parent: Node) -> Result<Origin, UrdfError> {
    let Some(o) = child(parent, "origin") else {
        return Ok(Origin::default());
    };
    let xyz = match o.attribute("xyz") {
        Some(s) => numbers(doc, o, "xyz", s)?,
        None => [0.0; 3],
    };
    let rpy = match o.attribute("rpy") {
        Some(s) => numbers(doc, o, "rpy", s)?,
        None => [0.0; 3],
    };
    Ok(Origin { xyz, rpy })
}

fn color(doc: &Document, material: Node) -> Result<Option<[u8; 3]>, UrdfError> {
    let Some(c) = child(material, "color") else {
        return Ok(None);
    };
    let rgba: [f64; 4] = number_attr(doc, c, "rgba")?;
    Ok(Some(
        [0, 1, 2].map(|i| (rgba[i].clamp(0.0, 1.0) * 255.0).round() as u8),
    ))
}

fn read_robot(doc: &Document) -> Result<Robot, UrdfError> {
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(UrdfError::NotRobot {
            found: root.tag_name().name().to_string(),
        });
    }
    let name = root.attribute("name").unwrap_or("robot").to_string();
    let elements = |tag: &'static str| {
        root.children()
            .filter(move |c| c.is_element() && c.tag_name().name() == tag)
    };
    let mut materials = HashMap::new();
    for m in elements("material") {
        if let (Some(name), Some(c)) = (m.attribute("name"), color(doc, m)?) {
            materials.insert(name.to_string(), c);
        }
    }
    let mut links = Vec::new();
    let mut seen = HashSet::new();
    for l in elements("link") {
        let name = attr(doc, l, "name")?.to_string();
        if !seen.insert(name.clone()) {
            return Err(UrdfError::Duplicate {
                line: line(doc, l),
                kind: "link",
                name,
            });
        }
        let inertial = match child(l, "inertial") {
            None => None,
            Some(i) => {
                let mass_node = child(i, "mass").ok_or_else(|| UrdfError::Missing {
                    line: line(doc, i),
                    what: format!("the `<inertial>` of link `{name}`"),
                    missing: "`<mass value=\"…\">`".to_string(),
                })?;
                let [mass] = number_attr(doc, mass_node, "value")?;
                let inertia = match child(i, "inertia") {
                    None => [0.0; 6],
                    Some(t) => {
                        let mut v = [0.0; 6];
                        for (k, a) in ["ixx", "iyy", "izz", "ixy", "ixz", "iyz"]
                            .iter()
                            .enumerate()
                        {
                            v[k] = optional_number(doc, t, a)?.unwrap_or(0.0);
                        }
                        v
                    }
                };
                Some(Inertial {
                    origin: origin(doc, i)?,
                    mass,
                    inertia,
                })
            }
        };
        let mut visuals = Vec::new();
        for v in l
            .children()
            .filter(|c| c.is_element() && c.tag_name().name() == "visual")
        {
            let Some(g) = child(v, "geometry") else {
                continue;
            };
            let Some(shape) = g.children().find(|c| c.is_element()) else {
                continue;
            };
            let geometry = match shape.tag_name().name() {
                "box" => Geometry::Box(number_attr(doc, shape, "size")?),
                "cylinder" => Geometry::Cylinder {
                    radius: number_attr::<1>(doc, shape, "radius")?[0],
                    length: number_attr::<1>(doc, shape, "length")?[0],
                },
                "sphere" => Geometry::Sphere(number_attr::<1>(doc, shape, "radius")?[0]),
                "mesh" => Geometry::Mesh(shape.attribute("filename").unwrap_or("?").to_string()),
                other => Geometry::Mesh(format!("<{other}>")),
            };
            let color = match child(v, "material") {
                None => None,
                Some(m) => match color(doc, m)? {
                    Some(c) => Some(c),
                    None => m.attribute("name").and_then(|n| materials.get(n).copied()),
                },
            };
            visuals.push(Visual {
                origin: origin(doc, v)?,
                geometry,
                color,
            });
        }
        links.push(Link {
            name,
            inertial,
            visuals,
        });
    }
    let mut joints = Vec::new();
    let mut seen = HashSet::new();
    for j in elements("joint") {
        let name = attr(doc, j, "name")?.to_string();
        if !seen.insert(name.clone()) {
            return Err(UrdfError::Duplicate {
                line: line(doc, j),
                kind: "joint",
                name,
            });
        }
        let kind = match attr(doc, j, "type")? {
            "revolute" => JointKind::Revolute,
            "continuous" => JointKind::Continuous,
            "prismatic" => JointKind::Prismatic,
            "fixed" => JointKind::Fixed,
            "floating" => JointKind::Floating,
            "planar" => JointKind::Planar,
            other => {
                return Err(UrdfError::UnsupportedJoint {
                    joint: name,
                    kind: other.to_string(),
                });
            }
        };
        let link_of = |role: &str| -> Result<String, UrdfError> {
            let n = child(j, role).ok_or_else(|| UrdfError::Missing {
                line: line(doc, j),
                what: format!("joint `{name}`"),
                missing: format!("`<{role} link=\"…\">`"),
            })?;
            Ok(attr(doc, n, "link")?.to_string())
        };
        let (parent, child_link) = (link_of("parent")?, link_of("child")?);
        let axis = match child(j, "axis") {
            Some(a) => number_attr(doc, a, "xyz")?,
            None => [1.0, 0.0, 0.0],
        };
        let limit = match child(j, "limit") {
            None => None,
            Some(l) => {
                let mut v = [None; 4];
                for (k, a) in ["lower", "upper", "effort", "velocity"].iter().enumerate() {
                    v[k] = optional_number(doc, l, a)?;
                }
                Some(v)
            }
        };
        let mimic = match child(j, "mimic") {
            None => None,
            Some(m) => Some(Mimic {
                leader: attr(doc, m, "joint")?.to_string(),
                multiplier: optional_number(doc, m, "multiplier")?.unwrap_or(1.0),
                offset: optional_number(doc, m, "offset")?.unwrap_or(0.0),
            }),
        };
        let (mut damping, mut friction) = (0.0, 0.0);
        if let Some(d) = child(j, "dynamics") {
            for (key, value) in [("damping", &mut damping), ("friction", &mut friction)] {
                *value = optional_number(doc, d, key)?.unwrap_or(0.0);
                if *value < 0.0 {
                    return Err(UrdfError::BadValue {
                        line: line(doc, d),
                        what: format!("`{key}` of the `<dynamics>` of joint `{name}`"),
                        value: num(*value),
                        expected: format!("a {key} coefficient ≥ 0"),
                    });
                }
            }
        }
        joints.push(Joint {
            name,
            kind,
            parent,
            child: child_link,
            origin: origin(doc, j)?,
            axis,
            limit,
            mimic,
            damping,
            friction,
        });
    }
    if links.is_empty() {
        return Err(UrdfError::NoLinks);
    }
    Ok(Robot {
        name,
        links,
        joints,
    })
}

// ---------------------------------------------------------------------------------------------
// The tree

/// The links as a tree: the root, each link's parent joint and child joints (document order),
/// checked for what the dynamics needs.
struct Tree {
    root: usize,
    /// the joints whose parent each link is
    children: Vec<Vec<usize>>,
    /// each link's index, by name
    link_index: HashMap<String, usize>,
    /// each joint's index, by name
    joint_index: HashMap<String, usize>,
}

fn did_you_mean<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> String {
    candidates
        .map(|c| (edit_distance::distance(name, c), c))
        .filter(|(d, c)| *d <= (name.len().max(c.len()) / 3).max(1))
        .min()
        .map(|(_, c)| format!("; did you mean `{c}`?"))
        .unwrap_or_else(|| "; declare it with `<link name=\"…\">`".to_string())
}

impl Tree {
    fn new(robot: &Robot) -> Result<Tree, UrdfError> {
        let n = robot.links.len();
        let link_index: HashMap<String, usize> = robot
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| (l.name.clone(), i))
            .collect();
        let joint_index: HashMap<String, usize> = robot
            .joints
            .iter()
            .enumerate()
            .map(|(i, j)| (j.name.clone(), i))
            .collect();
        let mut parent_joint: Vec<Option<usize>> = vec![None; n];
        let mut children = vec![Vec::new(); n];
        let find = |joint: &Joint, role: &'static str, link: &str| {
            link_index
                .get(link)
                .copied()
                .ok_or_else(|| UrdfError::UnknownLink {
                    joint: joint.name.clone(),
                    role,
                    link: link.to_string(),
                    hint: did_you_mean(link, robot.links.iter().map(|l| l.name.as_str())),
                })
        };
        for (k, j) in robot.joints.iter().enumerate() {
            let p = find(j, "parent", &j.parent)?;
            let c = find(j, "child", &j.child)?;
            if let Some(first) = parent_joint[c] {
                return Err(UrdfError::TwoParents {
                    link: j.child.clone(),
                    first: robot.joints[first].name.clone(),
                    second: j.name.clone(),
                });
            }
            parent_joint[c] = Some(k);
            children[p].push(k);
        }
        // every link has at most one parent: the links a root does not reach are on cycles
        let roots: Vec<usize> = (0..n).filter(|&i| parent_joint[i].is_none()).collect();
        let mut reached = vec![false; n];
        let mut stack = roots.clone();
        while let Some(i) = stack.pop() {
            reached[i] = true;
            stack.extend(
                children[i]
                    .iter()
                    .map(|&k| link_index[&robot.joints[k].child]),
            );
        }
        if let Some(start) = (0..n).find(|&i| !reached[i]) {
            // walk up from a link on (or below) a cycle until a link repeats
            let mut order = vec![start];
            let mut at = start;
            loop {
                let k = parent_joint[at].expect("an unreached link has a parent");
                at = link_index[&robot.joints[k].parent];
                if let Some(pos) = order.iter().position(|&l| l == at) {
                    let mut links: Vec<String> = order[pos..]
                        .iter()
                        .map(|&l| robot.links[l].name.clone())
                        .collect();
                    links.reverse();
                    return Err(UrdfError::Cycle { links });
                }
                order.push(at);
            }
        }
        if roots.len() != 1 {
            return Err(UrdfError::Roots {
                roots: roots.iter().map(|&i| robot.links[i].name.clone()).collect(),
            });
        }
        for (k, j) in robot.joints.iter().enumerate() {
            let moves_by_one = matches!(
                j.kind,
                JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic
            );
            if let (Some(m), false) = (&j.mimic, moves_by_one) {
                return Err(UrdfError::Mimic {
                    joint: j.name.clone(),
                    leader: m.leader.clone(),
                    problem: "but only revolute, continuous and prismatic joints can mimic; \
                              remove the `<mimic>`"
                        .to_string(),
                });
            }
            if matches!(j.kind, JointKind::Fixed | JointKind::Floating) {
                continue;
            }
            let length = norm(j.axis);
            if !(length >= 1e-12 && length.is_finite()) {
                return Err(UrdfError::ZeroAxis {
                    joint: j.name.clone(),
                    x: j.axis[0],
                    y: j.axis[1],
                    z: j.axis[2],
                });
            }
            if let Some(m) = &j.mimic {
                let problem = match joint_index.get(&m.leader) {
                    None => Some(
                        "which is not a joint of the robot; name an existing joint".to_string(),
                    ),
                    Some(&l) if l == k => Some("itself; name another joint".to_string()),
                    Some(&l) => {
                        let leader = &robot.joints[l];
                        if leader.mimic.is_some() {
                            Some(
                                "which mimics another joint itself; mimic that joint directly"
                                    .to_string(),
                            )
                        } else if !matches!(
                            leader.kind,
                            JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic
                        ) {
                            Some("which is not a revolute, continuous or prismatic joint; mimic one that is".to_string())
                        } else {
                            None
                        }
                    }
                };
                if let Some(problem) = problem {
                    return Err(UrdfError::Mimic {
                        joint: j.name.clone(),
                        leader: m.leader.clone(),
                        problem,
                    });
                }
            }
        }
        for l in &robot.links {
            let Some(i) = &l.inertial else { continue };
            if i.mass < 0.0 {
                return Err(UrdfError::NegativeMass {
                    link: l.name.clone(),
                    mass: i.mass,
                });
            }
        }
        let tree = Tree {
            root: roots[0],
            children,
            link_index,
            joint_index,
        };
        if robot
            .joints
            .iter()
            .all(|j| j.kind == JointKind::Fixed || j.mimic.is_some())
        {
            return Err(UrdfError::NoMotion);
        }
        // every joint with a coordinate moves some mass
        for j in &robot.joints {
            if j.kind == JointKind::Fixed || j.mimic.is_some() {
                continue;
            }
            let c = tree.link_index[&j.child];
            if !tree
                .subtree(robot, c)
                .iter()
                .any(|&l| mass_of(&robot.links[l]) > 0.0)
            {
                return Err(UrdfError::Massless {
                    joint: j.name.clone(),
                    link: j.child.clone(),
                });
            }
        }
        Ok(tree)
    }

    /// Link `l` and the links after it.
    fn subtree(&self, robot: &Robot, l: usize) -> Vec<usize> {
        let mut out = vec![l];
        let mut k = 0;
        while k < out.len() {
            for &j in &self.children[out[k]] {
                out.push(self.link_index[&robot.joints[j].child]);
            }
            k += 1;
        }
        out
    }
}

fn mass_of(l: &Link) -> f64 {
    l.inertial.as_ref().map_or(0.0, |i| i.mass)
}

// ---------------------------------------------------------------------------------------------
// Writing the model

/// What holds a link in the model.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Holder {
    Ground,
    /// an entity (body or frame), by index in `Writer::entities`
    Entity(usize),
}

/// A body or frame of the model: the link that starts it and the links merged into it.
struct Entity {
    /// the link whose frame it starts from
    link: usize,
    name: String,
    /// mass, centre of mass in the link frame, inertia about it in the link axes
    mass: f64,
    com: V3,
    inertia: M3,
    /// the links merged into it (fixed joints), with their pose in its link frame
    merged: Vec<(usize, Rigid)>,
    /// the centre of mass as the model writes it: a parameter or `0` per axis
    com_param: [String; 3],
}

/// Identifiers: URDF names made valid and unique.
#[derive(Default)]
struct Names {
    used: HashSet<String>,
}

const TAKEN: &[&str] = &[
    "t",
    "q",
    "qd",
    "qdd",
    "u",
    "PI",
    "E",
    "TAU",
    "ground",
    "TOG",
    "g",
    "sin",
    "cos",
    "tan",
    "asin",
    "acos",
    "atan",
    "atan2",
    "sinh",
    "cosh",
    "tanh",
    "exp",
    "ln",
    "sqrt",
    "abs",
    "sign",
    "pos",
    "step",
    "powi",
    "pow",
    "param",
    "let",
    "dof",
    "input",
    "body",
    "frame",
    "point",
    "effect",
    "scene",
    "constraint",
    "option",
    "shape",
    "model",
    "mass",
    "inertia",
    "gravity",
    "as",
    "break",
    "const",
    "continue",
    "crate",
    "else",
    "enum",
    "extern",
    "false",
    "fn",
    "for",
    "if",
    "impl",
    "in",
    "loop",
    "match",
    "mod",
    "move",
    "mut",
    "pub",
    "ref",
    "return",
    "self",
    "Self",
    "static",
    "struct",
    "super",
    "trait",
    "true",
    "type",
    "unsafe",
    "use",
    "where",
    "while",
    "async",
    "await",
    "dyn",
    "abstract",
    "become",
    "box",
    "do",
    "final",
    "macro",
    "override",
    "priv",
    "typeof",
    "unsized",
    "virtual",
    "yield",
    "try",
    "gen",
];

impl Names {
    fn new() -> Names {
        let mut n = Names::default();
        n.used.insert("g".to_string());
        n
    }

    /// A fresh identifier for `wanted` (other characters become `_`).
    fn fresh(&mut self, wanted: &str) -> String {
        let mut s: String = wanted
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) || s == "_" {
            s.insert_str(0, "l_");
        }
        if TAKEN.contains(&s.as_str()) {
            s.push('_');
        }
        let mut name = s.clone();
        let mut k = 2;
        while self.used.contains(&name) {
            name = format!("{s}_{k}");
            k += 1;
        }
        self.used.insert(name.clone());
        name
    }
}

/// A literal the DSL reads back exactly (negative ones in parentheses).
fn lit(x: f64) -> String {
    let x = if x == 0.0 { 0.0 } else { x };
    if x < 0.0 {
        format!("({x:?})")
    } else {
        format!("{x:?}")
    }
}

/// A number for a comment or a default: shortest form, no parentheses.
fn num(x: f64) -> String {
    let x = if x == 0.0 { 0.0 } else { x };
    format!("{x:?}")
}

/// Which unit coordinate axis `a` is (index, sign), if any.
fn coordinate_axis(a: V3) -> Option<(usize, f64)> {
    let k = (0..3).find(|&k| a[k].abs() == 1.0)?;
    (a.iter().enumerate().all(|(i, &x)| i == k || x == 0.0)).then_some((k, a[k]))
}

const AXES: [&str; 3] = ["x", "y", "z"];

struct Writer<'a> {
    robot: &'a Robot,
    tree: &'a Tree,
    names: Names,
    holder: Vec<Holder>,
    /// each link's pose in its holder's link frame
    in_holder: Vec<Rigid>,
    entities: Vec<Entity>,
    /// links merged into the ground (their mass does not move)
    on_ground: Vec<(usize, Rigid)>,
    /// the coordinates (or mimic expressions) of each joint
    motion: Vec<Vec<String>>,
    /// each link frame's pose as a product: a `TOG[…]` (none: the ground) and factors
    chain: HashMap<usize, (Option<String>, Vec<String>)>,
    /// whether a joint origin parameter was written
    joint_params: bool,
    params: String,
    dofs: String,
    items: String,
    shapes: String,
    /// the statements of the effects `joint_damping` and `joint_friction`
    damping: String,
    friction: String,
    /// the parameter of friction's regularisation, once written
    friction_eps: String,
}

impl<'a> Writer<'a> {
    fn new(robot: &'a Robot, tree: &'a Tree) -> Writer<'a> {
        let n = robot.links.len();
        Writer {
            robot,
            tree,
            names: Names::new(),
            holder: vec![Holder::Ground; n],
            in_holder: vec![Rigid::IDENTITY; n],
            entities: Vec::new(),
            on_ground: vec![(tree.root, Rigid::IDENTITY)],
            motion: vec![Vec::new(); robot.joints.len()],
            chain: HashMap::from([(tree.root, (None, Vec::new()))]),
            joint_params: false,
            params: String::new(),
            dofs: String::new(),
            items: String::new(),
            shapes: String::new(),
            damping: String::new(),
            friction: String::new(),
            friction_eps: String::new(),
        }
    }

    /// Links in depth-first order from the root (document order of the joints), with the joint
    /// they hang from.
    fn order(&self) -> Vec<(usize, Option<usize>)> {
        let mut out = Vec::new();
        let mut stack = vec![(self.tree.root, None)];
        while let Some((l, j)) = stack.pop() {
            out.push((l, j));
            for &k in self.tree.children[l].iter().rev() {
                stack.push((self.tree.link_index[&self.robot.joints[k].child], Some(k)));
            }
        }
        out
    }

    /// Decides which entity holds each link and gathers the merged masses.
    fn group(&mut self, order: &[(usize, Option<usize>)]) -> Result<(), UrdfError> {
        for &(l, j) in order {
            let Some(j) = j else { continue };
            let joint = &self.robot.joints[j];
            let parent = self.tree.link_index[&joint.parent];
            let link = &self.robot.links[l];
            if joint.kind == JointKind::Fixed && mass_of(link) > 0.0 {
                let pose = self.in_holder[parent].then(&Rigid::of(&joint.origin));
                self.holder[l] = self.holder[parent];
                self.in_holder[l] = pose;
                match self.holder[parent] {
                    Holder::Ground => self.on_ground.push((l, pose)),
                    Holder::Entity(e) => self.entities[e].merged.push((l, pose)),
                }
            } else {
                let name = self.names.fresh(&link.name);
                self.holder[l] = Holder::Entity(self.entities.len());
                self.entities.push(Entity {
                    link: l,
                    name,
                    mass: 0.0,
                    com: [0.0; 3],
                    inertia: [[0.0; 3]; 3],
                    merged: vec![(l, Rigid::IDENTITY)],
                    com_param: ["0", "0", "0"].map(String::from),
                });
            }
        }
        for e in &mut self.entities {
            let mut parts = Vec::new();
            for &(l, pose) in &e.merged {
                let Some(i) = &self.robot.links[l].inertial else {
                    continue;
                };
                if i.mass <= 0.0 {
                    continue;
                }
                let frame = pose.then(&Rigid::of(&i.origin));
                let [ixx, iyy, izz, ixy, ixz, iyz] = i.inertia;
                let local = [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]];
                let rotated = mul(&frame.r, &mul(&local, &transpose(&frame.r)));
                parts.push((i.mass, frame.p, rotated));
            }
            let mass: f64 = parts.iter().map(|p| p.0).sum();
            if mass <= 0.0 {
                continue;
            }
            let com = if parts.len() == 1 {
                parts[0].1
            } else {
                scale(
                    parts
                        .iter()
                        .fold([0.0; 3], |acc, p| add(acc, scale(p.1, p.0))),
                    1.0 / mass,
                )
            };
            let mut inertia = [[0.0; 3]; 3];
            for (m, p, i) in &parts {
                let d = sub(*p, com);
                let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                for r in 0..3 {
                    for c in 0..3 {
                        let shift = if parts.len() == 1 {
                            0.0
                        } else {
                            m * (if r == c { dd } else { 0.0 } - d[r] * d[c])
                        };
                        inertia[r][c] += i[r][c] + shift;
                    }
                }
            }
            e.mass = mass;
            e.com = com;
            e.inertia = inertia;
            // what `multibody!` accepts: no negative principal moment, the triangle inequality
            let t = [
                inertia[0][0],
                inertia[1][1],
                inertia[2][2],
                inertia[0][1],
                inertia[0][2],
                inertia[1][2],
            ];
            if let Some(problem) = crate::inertia::inertia_problem(t) {
                let [ixx, iyy, izz, ixy, ixz, iyz] = t;
                return Err(UrdfError::Inertia {
                    link: self.robot.links[e.link].name.clone(),
                    merged: e.merged[1..]
                        .iter()
                        .filter(|(l, _)| mass_of(&self.robot.links[*l]) > 0.0)
                        .map(|(l, _)| self.robot.links[*l].name.clone())
                        .collect(),
                    ixx,
                    iyy,
                    izz,
                    ixy,
                    ixz,
                    iyz,
                    problem,
                });
            }
        }
        Ok(())
    }

    fn write(mut self) -> Result<Imported, UrdfError> {
        let order = self.order();
        self.group(&order)?;
        let name = camel(&self.robot.name);
        // coordinates first (dofs are declared before the poses that use them)
        for &(_, j) in &order {
            if let Some(j) = j {
                self.declare_dofs(j);
            }
        }
        for &(_, j) in &order {
            if let Some(j) = j {
                self.resolve_mimic(j);
            }
        }
        let _ = writeln!(self.params, "        param g = 9.81;");
        for e in 0..self.entities.len() {
            self.declare_entity(e);
        }
        // poses, in depth-first order, as products from the holder's pose
        for &(l, j) in &order {
            if let Some(j) = j {
                self.pose(l, j);
            }
        }
        for &(_, j) in &order {
            if let Some(j) = j {
                self.joint_dynamics(j);
            }
        }
        let ground: Vec<(usize, Rigid)> = self.on_ground.clone();
        for &(l, pose) in &ground {
            let link = &self.robot.links[l];
            if mass_of(link) > 0.0 {
                let _ = writeln!(
                    self.shapes,
                    "        // link `{}` is fixed to the ground: its mass ({} kg) does not move",
                    link.name,
                    num(mass_of(link))
                );
            }
            self.visuals(l, pose, "ground", [0.0; 3]);
        }
        for e in 0..self.entities.len() {
            let (merged, name, com) = {
                let e = &self.entities[e];
                (e.merged.clone(), e.name.clone(), e.com)
            };
            for (l, pose) in merged {
                self.visuals(l, pose, &name, com);
            }
        }
        let mut s = String::new();
        let _ = writeln!(
            s,
            "    /// The `{}` robot, imported from its URDF description.",
            self.robot.name
        );
        let _ = writeln!(s, "    pub model {name} {{");
        s.push_str(&self.params);
        s.push_str(&self.dofs);
        s.push_str(&self.items);
        s.push_str(&self.shapes);
        s.push_str("        gravity(0, 0, -g);\n");
        for (name, forces) in [
            ("joint_damping", &self.damping),
            ("joint_friction", &self.friction),
        ] {
            if !forces.is_empty() {
                let name = self.names.fresh(name);
                let _ = writeln!(s, "        effect {name} {{");
                s.push_str(forces);
                s.push_str("        }\n");
            }
        }
        s.push_str("    }\n");
        Ok(Imported { name, model: s })
    }

    fn declare_dofs(&mut self, j: usize) {
        let joint = &self.robot.joints[j];
        if joint.mimic.is_some() {
            return;
        }
        let limits = joint.limit.map(|[lo, up, effort, velocity]| {
            let unit = if joint.kind == JointKind::Prismatic {
                ("m", "N", "m/s")
            } else {
                ("rad", "N·m", "rad/s")
            };
            let mut parts = Vec::new();
            if joint.kind != JointKind::Continuous
                && let (Some(lo), Some(up)) = (lo, up)
            {
                parts.push(format!("limits [{}, {}] {}", num(lo), num(up), unit.0));
            }
            if let Some(e) = effort {
                parts.push(format!("effort {} {}", num(e), unit.1));
            }
            if let Some(v) = velocity {
                parts.push(format!("velocity {} {}", num(v), unit.2));
            }
            parts.join(", ")
        });
        let start = match joint.limit {
            Some([Some(lo), Some(up), ..]) if joint.kind != JointKind::Continuous && lo <= up => {
                0.0f64.clamp(lo, up)
            }
            _ => 0.0,
        };
        let what = match joint.kind {
            JointKind::Revolute => "revolute",
            JointKind::Continuous => "continuous",
            JointKind::Prismatic => "prismatic",
            JointKind::Floating => {
                let names: Vec<String> = ["x", "y", "z", "roll", "pitch", "yaw"]
                    .iter()
                    .map(|s| self.names.fresh(&format!("{}_{s}", joint.name)))
                    .collect();
                let _ = writeln!(
                    self.dofs,
                    "        // floating joint `{}`: position in the axes of its `<origin>`, then Euler angles about \
                     z (yaw), y (pitch), x (roll)\n        // read in a chart the runtime re-centres \
                     before pitch reaches ±π/2 (`Tfree`)",
                    joint.name
                );
                for n in &names {
                    let _ = writeln!(self.dofs, "        dof {n} = 0.0;");
                }
                self.motion[j] = names;
                return;
            }
            JointKind::Planar => {
                let names: Vec<String> = ["x", "y", "theta"]
                    .iter()
                    .map(|s| self.names.fresh(&format!("{}_{s}", joint.name)))
                    .collect();
                let a = unit(joint.axis);
                let plane = match coordinate_axis(a) {
                    Some((2, _)) => "along x and y".to_string(),
                    _ => {
                        let (u, v) = plane_basis(a);
                        let show = |w: V3| format!("({}, {}, {})", num(w[0]), num(w[1]), num(w[2]));
                        format!("along u = {} and v = {}", show(u), show(v))
                    }
                };
                let _ = writeln!(
                    self.dofs,
                    "        // planar joint `{}`: translations {plane} (in the plane normal to \
                     the axis), then the rotation about the axis",
                    joint.name
                );
                for n in &names {
                    let _ = writeln!(self.dofs, "        dof {n} = 0.0;");
                }
                self.motion[j] = names;
                return;
            }
            JointKind::Fixed => return,
        };
        let n = self.names.fresh(&joint.name);
        let comment = match limits {
            Some(l) if !l.is_empty() => format!(" // {what}, {l}"),
            _ => format!(" // {what}"),
        };
        let _ = writeln!(self.dofs, "        dof {n} = {};{comment}", num(start));
        self.motion[j] = vec![n];
    }

    fn resolve_mimic(&mut self, j: usize) {
        let joint = &self.robot.joints[j];
        let Some(m) = &joint.mimic else { return };
        let leader = &self.motion[self.tree.joint_index[&m.leader]][0];
        let mut e = if m.multiplier == 1.0 {
            leader.clone()
        } else {
            format!("{} * {leader}", lit(m.multiplier))
        };
        if m.offset != 0.0 {
            e = format!("{e} + {}", lit(m.offset));
        }
        let _ = writeln!(
            self.dofs,
            "        // joint `{}` mimics `{}`: its motion is {e}",
            joint.name, m.leader
        );
        let bare = m.multiplier == 1.0 && m.offset == 0.0;
        self.motion[j] = vec![if bare { e } else { format!("({e})") }];
    }

    /// The damping and Coulomb friction of joint `j`'s `<dynamics>` as generalised forces on
    /// its coordinate (for a mimic joint, on its leader's, times the multiplier: the power is
    /// the same), in the effects `joint_damping` and `joint_friction`.
    fn joint_dynamics(&mut self, j: usize) {
        let joint = &self.robot.joints[j];
        let (c, f) = (joint.damping, joint.friction);
        if c == 0.0 && f == 0.0 || joint.kind == JointKind::Fixed {
            return;
        }
        if matches!(joint.kind, JointKind::Floating | JointKind::Planar) {
            let _ = writeln!(
                self.shapes,
                "        // joint `{}`: the damping and friction of its `<dynamics>` are not applied \
                 to a floating or planar joint (add `generalized_force`s or a `bushing`)",
                joint.name
            );
            return;
        }
        let (coordinate, speed, multiplier) = match &joint.mimic {
            Some(m) => {
                let leader = self.motion[self.tree.joint_index[&m.leader]][0].clone();
                let speed = if m.multiplier == 1.0 {
                    format!("qd[{leader}]")
                } else {
                    format!("{} * qd[{leader}]", lit(m.multiplier))
                };
                (leader, speed, (m.multiplier != 1.0).then_some(m.multiplier))
            }
            None => {
                let q = self.motion[j][0].clone();
                (q.clone(), format!("qd[{q}]"), None)
            }
        };
        let units = if joint.kind == JointKind::Prismatic {
            ("N·s/m", "N")
        } else {
            ("N·m·s/rad", "N·m")
        };
        let _ = writeln!(
            self.params,
            "        // joint `{}`: damping ({}) and Coulomb friction ({}) of its `<dynamics>`",
            joint.name, units.0, units.1
        );
        let on = |force: String| match multiplier {
            Some(m) => format!("{} * ({force})", lit(m)),
            None => force,
        };
        let name = joint.name.clone();
        if c > 0.0 {
            let p = self.names.fresh(&format!("{name}_damping"));
            let _ = writeln!(self.params, "        param {p} = {};", num(c));
            let force = on(format!("-{p} * {speed}"));
            let _ = writeln!(
                self.damping,
                "            generalized_force({coordinate}, {force});"
            );
        }
        if f > 0.0 {
            if self.friction_eps.is_empty() {
                self.friction_eps = self.names.fresh("joint_friction_eps");
                let _ = writeln!(
                    self.params,
                    "        // the speed (rad/s or m/s) below which joint friction is viscous: \
                     f tanh(v / eps)\n        param {} = 0.01;",
                    self.friction_eps
                );
            }
            let p = self.names.fresh(&format!("{name}_friction"));
            let _ = writeln!(self.params, "        param {p} = {};", num(f));
            let eps = &self.friction_eps;
            let force = on(format!("-{p} * tanh({speed} / {eps})"));
            let _ = writeln!(
                self.friction,
                "            generalized_force({coordinate}, {force});"
            );
        }
    }

    fn declare_entity(&mut self, e: usize) {
        let en = &self.entities[e];
        let name = en.name.clone();
        let merged: Vec<&str> = en.merged[1..]
            .iter()
            .filter(|(l, _)| mass_of(&self.robot.links[*l]) > 0.0)
            .map(|(l, _)| self.robot.links[*l].name.as_str())
            .collect();
        if en.mass <= 0.0 {
            let _ = writeln!(self.items, "        frame {name};");
            return;
        }
        let link = &self.robot.links[en.link].name;
        let _ = write!(
            self.params,
            "        // link `{link}`: mass (kg), centre of mass in the link frame (m), inertia about it (kg·m²)"
        );
        if !merged.is_empty() {
            let _ = write!(
                self.params,
                "\n        // (with {}, fixed to it)",
                merged
                    .iter()
                    .map(|m| format!("`{m}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        self.params.push('\n');
        let (mass, com) = (en.mass, en.com);
        let mname = self.names.fresh(&format!("{name}_m"));
        let _ = writeln!(self.params, "        param {mname} = {};", num(mass));
        for (k, ax) in AXES.iter().enumerate() {
            if com[k] != 0.0 {
                let c = self.names.fresh(&format!("{name}_c{ax}"));
                let _ = writeln!(self.params, "        param {c} = {};", num(com[k]));
                self.entities[e].com_param[k] = c;
            }
        }
        let en = &self.entities[e];
        let i = en.inertia;
        let entries = [i[0][0], i[1][1], i[2][2], i[0][1], i[0][2], i[1][2]];
        let full = entries[3..].iter().any(|&x| x != 0.0);
        let point = entries.iter().all(|&x| x == 0.0);
        let mut inertia_names = Vec::new();
        if !point {
            let count = if full { 6 } else { 3 };
            for (k, tag) in ["ixx", "iyy", "izz", "ixy", "ixz", "iyz"][..count]
                .iter()
                .enumerate()
            {
                if entries[k] == 0.0 {
                    inertia_names.push("0".to_string());
                    continue;
                }
                let p = self.names.fresh(&format!("{name}_{tag}"));
                let _ = writeln!(self.params, "        param {p} = {};", num(entries[k]));
                inertia_names.push(p);
            }
        }
        let inertia = if point {
            String::new()
        } else {
            format!(" inertia = ({});", inertia_names.join(", "))
        };
        let _ = writeln!(
            self.items,
            "        body {name} {{ mass = {mname};{inertia} }}"
        );
    }

    /// The factors of joint `j`'s origin and motion.
    fn joint_factors(&mut self, j: usize) -> Vec<String> {
        let joint = &self.robot.joints[j];
        let mut f = Vec::new();
        let xyz = joint.origin.xyz;
        // the origin of a fixed joint whose link is merged into its parent's body stays a
        // number: the merged mass, centre and inertia were computed with it
        let child = &self.robot.links[self.tree.link_index[&joint.child]];
        let merged = joint.kind == JointKind::Fixed && mass_of(child) > 0.0;
        if xyz != [0.0; 3] && merged {
            let parts = xyz.map(|x| if x == 0.0 { "0".to_string() } else { lit(x) });
            f.push(format!("Tdisp({})", parts.join(", ")));
        } else if xyz != [0.0; 3] {
            if !self.joint_params {
                self.joint_params = true;
                self.params
                    .push_str("        // joint origins in the parent link frame (m)\n");
            }
            let mut parts = Vec::new();
            for (k, ax) in AXES.iter().enumerate() {
                if xyz[k] == 0.0 {
                    parts.push("0".to_string());
                } else {
                    let p = self.names.fresh(&format!("{}_d{ax}", joint.name));
                    let _ = writeln!(self.params, "        param {p} = {};", num(xyz[k]));
                    parts.push(p);
                }
            }
            f.push(format!("Tdisp({})", parts.join(", ")));
        }
        let rpy = joint.origin.rpy;
        for (k, ax) in [(2, "z"), (1, "y"), (0, "x")] {
            if rpy[k] != 0.0 {
                f.push(format!("Trot{ax}({})", num(rpy[k])));
            }
        }
        let m = &self.motion[j];
        let a = if joint.kind == JointKind::Floating {
            joint.axis
        } else {
            unit(joint.axis)
        };
        match joint.kind {
            JointKind::Fixed => {}
            JointKind::Revolute | JointKind::Continuous => {
                let q = &m[0];
                f.push(match coordinate_axis(a) {
                    Some((k, s)) if s > 0.0 => format!("Trot{}({q})", AXES[k]),
                    Some((k, _)) => format!("Trot{}(-{q})", AXES[k]),
                    None => format!("Trotn({}, {}, {}, {q})", lit(a[0]), lit(a[1]), lit(a[2])),
                });
            }
            JointKind::Prismatic => {
                let q = &m[0];
                f.push(match coordinate_axis(a) {
                    Some((k, s)) => {
                        let mut parts = vec!["0".to_string(); 3];
                        parts[k] = if s > 0.0 { q.clone() } else { format!("-{q}") };
                        format!("Tdisp({})", parts.join(", "))
                    }
                    None => format!(
                        "Tdisp({} * {q}, {} * {q}, {} * {q})",
                        lit(a[0]),
                        lit(a[1]),
                        lit(a[2])
                    ),
                });
            }
            JointKind::Floating => {
                f.push(format!(
                    "Tfree({}, {}, {}, {}, {}, {})",
                    m[0], m[1], m[2], m[5], m[4], m[3]
                ));
            }
            JointKind::Planar => {
                let (x, y, th) = (&m[0], &m[1], &m[2]);
                match coordinate_axis(a) {
                    Some((2, s)) => {
                        f.push(format!("Tdisp({x}, {y}, 0)"));
                        f.push(if s > 0.0 {
                            format!("Trotz({th})")
                        } else {
                            format!("Trotz(-{th})")
                        });
                    }
                    _ => {
                        let (u, v) = plane_basis(a);
                        let c = |k: usize| {
                            let term = |w: f64, q: &str| match w {
                                1.0 => q.to_string(),
                                -1.0 => format!("-{q}"),
                                _ => format!("{} * {q}", lit(w)),
                            };
                            let mut terms = Vec::new();
                            if u[k] != 0.0 {
                                terms.push(term(u[k], x));
                            }
                            if v[k] != 0.0 {
                                terms.push(term(v[k], y));
                            }
                            if terms.is_empty() {
                                "0".to_string()
                            } else {
                                terms.join(" + ")
                            }
                        };
                        f.push(format!("Tdisp({}, {}, {})", c(0), c(1), c(2)));
                        f.push(match coordinate_axis(a) {
                            Some((k, s)) if s > 0.0 => format!("Trot{}({th})", AXES[k]),
                            Some((k, _)) => format!("Trot{}(-{th})", AXES[k]),
                            None => {
                                format!("Trotn({}, {}, {}, {th})", lit(a[0]), lit(a[1]), lit(a[2]))
                            }
                        });
                    }
                }
            }
        }
        f
    }

    fn pose(&mut self, l: usize, j: usize) {
        let parent = self.tree.link_index[&self.robot.joints[j].parent];
        let (base, mut factors) = self.chain[&parent].clone();
        factors.extend(self.joint_factors(j));
        match self.holder[l] {
            Holder::Entity(e) if self.entities[e].link == l => {
                let en = &self.entities[e];
                let name = en.name.clone();
                let moved = en.mass > 0.0 && en.com != [0.0; 3];
                let com = format!("Tdisp({})", en.com_param.join(", "));
                if moved && !self.tree.children[l].is_empty() {
                    // links hang from the link frame: a frame of its own, shared by the body
                    // and the children (cheaper than going back from G)
                    let link = self.names.fresh(&format!("{name}_frame"));
                    let text = product(base.as_deref(), &factors);
                    let _ = writeln!(self.items, "        frame {link};");
                    let _ = writeln!(self.items, "        TOG[{link}] = {text};");
                    let _ = writeln!(self.items, "        TOG[{name}] = TOG[{link}] * {com};");
                    self.chain
                        .insert(l, (Some(format!("TOG[{link}]")), Vec::new()));
                } else {
                    if moved {
                        factors.push(com);
                    }
                    let text = product(base.as_deref(), &factors);
                    let _ = writeln!(self.items, "        TOG[{name}] = {text};");
                    self.chain
                        .insert(l, (Some(format!("TOG[{name}]")), Vec::new()));
                }
            }
            _ => {
                self.chain.insert(l, (base, factors));
            }
        }
    }

    /// The `shape` statements of link `l`'s visuals, drawn with `holder` whose origin is at
    /// `origin` in the holder's link frame; `pose` is `l`'s frame in that link frame.
    fn visuals(&mut self, l: usize, pose: Rigid, holder: &str, origin: V3) {
        let link = &self.robot.links[l];
        for v in &link.visuals {
            let frame = pose.then(&Rigid::of(&v.origin));
            let at = sub(frame.p, origin);
            let mut tail = String::new();
            if at != [0.0; 3] {
                let _ = write!(
                    tail,
                    ", at = ({}, {}, {})",
                    lit(at[0]),
                    lit(at[1]),
                    lit(at[2])
                );
            }
            if let Some([r, g, b]) = v.color {
                let _ = write!(tail, ", color = \"#{r:02x}{g:02x}{b:02x}\"");
            }
            let r = &frame.r;
            // which holder axis each of the visual's axes lies along, if they are aligned
            let along = |k: usize| -> Option<usize> {
                (0..3).find(|&i| (r[i][k].abs() - 1.0).abs() < 1e-9)
            };
            let sizes: &[f64] = match &v.geometry {
                Geometry::Sphere(r) => std::slice::from_ref(r),
                Geometry::Box(size) => size,
                Geometry::Cylinder { radius, length } => &[*radius, *length],
                Geometry::Mesh(_) => &[],
            };
            if sizes.iter().any(|&x| x <= 0.0) {
                let _ = writeln!(
                    self.shapes,
                    "        // link `{}`: a visual with a size that is not positive is not drawn",
                    link.name
                );
                continue;
            }
            let statement = match &v.geometry {
                Geometry::Sphere(radius) => Some(format!("sphere({}{tail})", num(*radius))),
                Geometry::Box(size) => {
                    let axes = [along(0), along(1), along(2)];
                    match axes {
                        [Some(a), Some(b), Some(c)] => {
                            let mut sides = [0.0; 3];
                            sides[a] = size[0];
                            sides[b] = size[1];
                            sides[c] = size[2];
                            Some(format!(
                                "box({}, {}, {}{tail})",
                                num(sides[0]),
                                num(sides[1]),
                                num(sides[2])
                            ))
                        }
                        _ => None,
                    }
                }
                Geometry::Cylinder { radius, length } => along(2).map(|a| {
                    format!(
                        "cylinder({}, {}, axis = {}{tail})",
                        num(*radius),
                        num(*length),
                        AXES[a]
                    )
                }),
                Geometry::Mesh(file) => {
                    let _ = writeln!(
                        self.shapes,
                        "        // link `{}`: mesh {file} is not drawn; add shape statements",
                        link.name
                    );
                    continue;
                }
            };
            match statement {
                Some(s) => {
                    let _ = writeln!(self.shapes, "        shape {holder}: {s};");
                }
                None => {
                    let _ = writeln!(
                        self.shapes,
                        "        // link `{}`: a visual turned off the link's axes is not drawn",
                        link.name
                    );
                }
            }
        }
    }
}

fn product(base: Option<&str>, factors: &[String]) -> String {
    let mut all: Vec<&str> = base.into_iter().collect();
    all.extend(factors.iter().map(String::as_str));
    if all.is_empty() {
        "Tdisp(0, 0, 0)".to_string()
    } else {
        all.join(" * ")
    }
}

/// The unit normal of a planar joint's axis and an orthonormal basis (u, v) of its plane.
fn plane_basis(a: V3) -> (V3, V3) {
    let helper = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let cross = |p: V3, q: V3| {
        [
            p[1] * q[2] - p[2] * q[1],
            p[2] * q[0] - p[0] * q[2],
            p[0] * q[1] - p[1] * q[0],
        ]
    };
    let u0 = cross(helper, a);
    let un = (u0[0] * u0[0] + u0[1] * u0[1] + u0[2] * u0[2]).sqrt();
    let u = scale(u0, 1.0 / un);
    (u, cross(a, u))
}

fn unit(a: V3) -> V3 {
    scale(a, 1.0 / norm(a))
}

/// |a|: the plain root of the sum of squares, or `hypot`'s where that sum overflows or
/// underflows (entries near ±f64::MAX or below 1e-150).
fn norm(a: V3) -> f64 {
    let plain = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    if plain.is_finite() && plain > 1e-150 {
        plain
    } else {
        a[0].hypot(a[1]).hypot(a[2])
    }
}

/// `ur5_robot` → `Ur5Robot`.
fn camel(name: &str) -> String {
    let mut s = String::new();
    let mut up = true;
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            if up {
                s.push(c.to_ascii_uppercase());
            } else {
                s.push(c);
            }
            up = false;
        } else {
            up = true;
        }
    }
    // `Self` is a keyword, not a type name a model may take
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) || s == "Self" {
        s.insert_str(0, "Robot");
    }
    s
}
