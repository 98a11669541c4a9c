//! Shapes in the DSL, the HTML animation and the glTF file: a crane (a cart on a rail with a
//! rod and a bob, every kind of shape) is simulated with poses recorded; its shapes in
//! `ModelInfo` are those declared (plus the rod's equivalent box), the page is self-contained
//! and carries the poses, the glTF parses back, is consistent and samples the same poses.
//! With Chromium on PATH the page is also loaded headless: no console error, its frame count
//! in the DOM, a picture that is not blank. Without a browser that test says so loudly and
//! passes, except under CI (`CI=true`) or with `MBS_REQUIRE_BROWSER=1` (`.ci/run`), where it
//! fails.

use mbs::anim::{AnimOptions, ExportError, Up};
use mbs::gltf::GltfOptions;
use mbs::{Model, Options, Output, Pose, Scheme, ShapeKind, Trajectory};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use mbs_models::dpend;

mbs::multibody! {
    /// A cart on a rail carrying a pendulum (a rod and a bob) that swings about x.
    model Crane {
        param l = 0.8; param m = 1.0;
        dof x = 0.0, qd = 0.5; dof theta = 0.6;
        body cart { mass = 2.0; inertia = (0.01, 0.03, 0.03); }
        body rod { mass = 0.1; inertia = (0.1 * l * l / 12, 0.1 * l * l / 12, 0); }
        body bob { mass = m; inertia = (0.004, 0.004, 0.004); }
        frame hook;
        TOG[cart] = Tdisp(x, 0, 0.5);
        TOG[hook] = TOG[cart] * Tdisp(0, 0, -0.05);
        TOG[rod] = TOG[cart] * Trotx(theta) * Tdisp(0, 0, -l / 2);
        TOG[bob] = TOG[rod] * Tdisp(0, 0, -l / 2);
        shape cart: box(0.4, 0.2, 0.1, color = "#3366cc");
        shape cart: cylinder(0.05, 0.25, axis = y, at = (0.15, 0, -0.05));
        shape bob: sphere(0.08, color = "#cc3333");
        shape hook: line(from = (0, 0, 0), to = (0, 0, -l / 2));
        shape ground: box(4, 0.1, 0.02, at = (0, 0, 0.44), color = "#777777");
        gravity(0, 0, -9.81);
    }
}

const EYE: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn crane_run() -> (Crane, Trajectory) {
    let model = Crane::default();
    let options = Options {
        frames: true,
        output: Output::Every { dt: 0.01 },
        ..Options::adaptive(1.0, 1e-8)
    };
    let (tr, _) = mbs::simulate(model.clone(), Scheme::Dopri5, options).expect("the crane runs");
    (model, tr)
}

fn out_dir(name: &str) -> PathBuf {
    // target/tmp/animation/NAME, kept for a look after the run
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("animation")
        .join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

/// The rotation of a unit quaternion (x, y, z, w).
fn rotation(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [x, y, z, w] = q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

fn same_rotation(q: [f64; 4], pose: &Pose, tol: f64) {
    let r = rotation(q);
    for (row, expected) in r.iter().zip(&pose.rotation) {
        for (a, b) in row.iter().zip(expected) {
            assert!(
                (a - b).abs() < tol,
                "quaternion {q:?} is not the rotation {:?}",
                pose.rotation
            );
        }
    }
}

#[test]
fn shapes_in_model_info_are_as_declared() {
    let info = Crane::default().info();
    let idx = |n: &str| info.frame_index(n);
    let declared: Vec<_> = info.shapes.iter().filter(|s| s.declared).collect();
    assert_eq!(declared.len(), 5, "{:#?}", info.shapes);
    let s = declared[0];
    assert_eq!(s.frame, idx("cart"));
    assert_eq!(
        s.kind,
        ShapeKind::Box {
            size: [0.4, 0.2, 0.1]
        }
    );
    assert_eq!(
        (s.at, s.color, s.rotation),
        ([0.0; 3], Some([0x33, 0x66, 0xcc]), EYE)
    );
    let s = declared[1];
    assert_eq!(s.frame, idx("cart"));
    assert_eq!(
        s.kind,
        ShapeKind::Cylinder {
            radius: 0.05,
            length: 0.25,
            axis: 1
        }
    );
    assert_eq!((s.at, s.color), ([0.15, 0.0, -0.05], None));
    let s = declared[2];
    assert_eq!(s.frame, idx("bob"));
    assert_eq!(s.kind, ShapeKind::Sphere { radius: 0.08 });
    assert_eq!(s.color, Some([0xcc, 0x33, 0x33]));
    // a parameter in a shape takes its default value
    let s = declared[3];
    assert_eq!(s.frame, idx("hook"));
    assert_eq!(
        s.kind,
        ShapeKind::Line {
            from: [0.0; 3],
            to: [0.0, 0.0, -0.4]
        }
    );
    let s = declared[4];
    assert_eq!(s.frame, None, "on the ground");
    assert_eq!(
        s.kind,
        ShapeKind::Box {
            size: [4.0, 0.1, 0.02]
        }
    );
    assert_eq!(s.at, [0.0, 0.0, 0.44]);
    // the rod declares none: its equivalent box, a bar 0.8 long along z, 4 % as thick
    let defaults: Vec<_> = info.shapes.iter().filter(|s| !s.declared).collect();
    assert_eq!(
        defaults.len(),
        1,
        "only the rod has no shape (hook is a frame)"
    );
    assert_eq!(defaults[0].frame, idx("rod"));
    let ShapeKind::Box { size } = defaults[0].kind else {
        panic!("{:?}", defaults[0])
    };
    for (a, b) in size.iter().zip([0.032, 0.032, 0.8]) {
        assert!(close(*a, b, 1e-12), "{size:?}");
    }
    // dpend declares no shape: two bars 1 m long along y
    let info = dpend::DoublePendulum::default().info();
    assert_eq!(info.shapes.len(), 2);
    for (i, s) in info.shapes.iter().enumerate() {
        assert_eq!((s.frame, s.declared), (Some(i), false));
        let ShapeKind::Box { size } = s.kind else {
            panic!()
        };
        assert!(
            close(size[1], 1.0, 1e-12) && close(size[0], 0.04, 1e-12),
            "{size:?}"
        );
    }
}

#[test]
fn quaternions_of_poses_give_back_their_rotations() {
    let (model, tr) = crane_run();
    let mut n = 0;
    for i in (0..tr.len()).step_by(7) {
        for p in tr.poses_at(i) {
            let q = p.quaternion();
            assert!(q[3] >= 0.0);
            same_rotation(q, p, 1e-12);
            n += 1;
        }
    }
    assert!(n > 10);
    // and of a half turn, where w = 0
    let half = Pose {
        rotation: [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]],
        position: [0.0; 3],
    };
    same_rotation(half.quaternion(), &half, 1e-15);
    let _ = model;
}

/// The JSON the page embeds.
fn page_data(html: &str) -> serde_json::Value {
    let open = r#"<script type="application/json" id="mbs-data">"#;
    let start = html.find(open).expect("the data block") + open.len();
    let end = start + html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..end].replace("<\\/", "</")).expect("the data is JSON")
}

fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn the_page_is_self_contained_and_carries_the_poses() {
    let (model, tr) = crane_run();
    let info = model.info();
    let dir = out_dir("page");
    let path = dir.join("crane.html");
    mbs::anim::write_html(&path, info, &tr).unwrap();
    let html = std::fs::read_to_string(&path).unwrap();
    for outside in [
        "http://", "https://", "src=", "@import", "url(", "//cdn", "<iframe",
    ] {
        assert!(
            !html.contains(outside),
            "the page refers outside: `{outside}`"
        );
    }
    for (k, _) in html.match_indices("href=") {
        assert!(
            html[k..].starts_with("href=\"data:"),
            "a link out of the page"
        );
    }
    assert!(html.contains("window.mbsFrameCount = N"));
    assert!(html.contains("<canvas") && html.contains("id=\"scrub\""));
    let d = page_data(&html);
    assert_eq!(d["model"], "Crane");
    assert_eq!(d["up"], "z", "the crane moves out of the xy plane");
    let n = tr.len();
    let nf = info.frames.len();
    let t = floats(&d["t"]);
    assert_eq!(t.len(), n, "one frame per output");
    for (a, b) in t.iter().zip(&tr.t) {
        assert!((a - b).abs() < 1e-12, "time {a} for {b}");
    }
    let p = floats(&d["p"]);
    assert_eq!(p.len(), 7 * n * nf);
    let decimals = d["decimals"].as_u64().unwrap() as i32;
    let tol = 0.51 * 10f64.powi(-decimals);
    for i in 0..n {
        for (f, pose) in tr.poses_at(i).iter().enumerate() {
            let k = 7 * (i * nf + f);
            for c in 0..3 {
                assert!(
                    (p[k + 4 + c] - pose.position[c]).abs() <= tol,
                    "output {i}, frame {f}"
                );
            }
            let q = [p[k], p[k + 1], p[k + 2], p[k + 3]];
            same_rotation(q, pose, 1e-6);
        }
    }
    // one entry per shape, with its frame (-1: the ground) and its colour
    let shapes = d["shapes"].as_array().unwrap();
    assert_eq!(shapes.len(), info.shapes.len());
    assert_eq!(shapes[0]["c"], "#3366cc");
    assert_eq!(shapes[4]["f"], -1);
    assert_eq!(
        shapes[3]["l"].as_array().unwrap().len(),
        1,
        "a line is a segment"
    );
    assert_eq!(
        shapes[0]["q"].as_array().unwrap().len(),
        6,
        "a box has 6 faces"
    );
    // a planar model is seen with y up
    let dp = dpend_run(2.0);
    let page = mbs::anim::html(
        dpend::DoublePendulum::default().info(),
        &dp,
        &AnimOptions::default(),
    )
    .unwrap();
    assert_eq!(page_data(&page)["up"], "y");
    // thinning keeps the first and the last output
    let few = AnimOptions {
        max_frames: 10,
        up: Up::Z,
        ..AnimOptions::default()
    };
    let d = page_data(&mbs::anim::html(info, &tr, &few).unwrap());
    let t = floats(&d["t"]);
    assert_eq!((t.len(), t[0], t[9]), (10, tr.t[0], tr.t[n - 1]));
}

fn dpend_run(t_end: f64) -> Trajectory {
    let options = Options {
        frames: true,
        ..Options::adaptive(t_end, 1e-6)
    };
    mbs::simulate(dpend::DoublePendulum::default(), Scheme::Dopri5, options)
        .unwrap()
        .0
}

#[test]
fn exports_without_poses_say_how_to_record_them() {
    let model = Crane::default();
    let (tr, _) =
        mbs::simulate(model.clone(), Scheme::Dopri5, Options::adaptive(0.1, 1e-6)).unwrap();
    let dir = out_dir("no-poses");
    let e = mbs::anim::write_html(&dir.join("a.html"), model.info(), &tr).unwrap_err();
    assert!(matches!(e, ExportError::NoPoses), "{e}");
    assert!(e.to_string().contains("frames: true"));
    let e = mbs::gltf::write_gltf(&dir.join("a.gltf"), model.info(), &tr).unwrap_err();
    assert!(matches!(e, ExportError::NoPoses));
    let dp = dpend_run(0.1);
    let e = mbs::anim::write_html(&dir.join("b.html"), model.info(), &dp).unwrap_err();
    assert!(matches!(e, ExportError::Frames { .. }), "{e}");
}

/// glTF's times and positions are 32-bit: outputs that its times cannot tell apart are
/// skipped (strictly increasing times, as the format asks), and a value beyond f32 is a typed
/// error naming the output, not a `null` in the file.
#[test]
fn the_gltf_keeps_its_32_bit_times_increasing_and_refuses_what_f32_cannot_hold() {
    let info = dpend::DoublePendulum::default().info();
    let mut tr = dpend_run(5.0);
    let n = tr.len();
    assert!(n > 100, "{n} outputs");
    // the first output at 0, the others 10⁴ s later, 1e-5 s apart: at 10⁴ s f32 times are
    // 2^-10 s apart, so about one output in 98 keeps a time of its own
    for (k, t) in tr.t.iter_mut().enumerate().skip(1) {
        *t = 1e4 + k as f64 * 1e-5;
    }
    let root = mbs::gltf::document(info, &tr, &GltfOptions::default()).unwrap();
    let anim = &root.animations[0];
    let input = &root.accessors[anim.samplers[0].input.value()];
    let kept = input.count.0 as usize;
    assert!(kept >= 2 && kept < n, "{kept} of {n} outputs kept");
    let min = input.min.as_ref().unwrap()[0].as_f64().unwrap();
    let max = input.max.as_ref().unwrap()[0].as_f64().unwrap();
    assert_eq!(min, 0.0);
    assert!((max - 1e4).abs() < 0.01, "{max}");

    // a position beyond f32 (3.4e38): refused, naming the frame and the output
    let mut far = dpend_run(0.1);
    let nf = info.frames.len();
    far.poses[5 * nf + 1].position[0] = 1e39;
    let e = mbs::gltf::document(info, &far, &GltfOptions::default()).unwrap_err();
    assert!(
        matches!(e, ExportError::BeyondSinglePrecision { output: 5, .. }),
        "{e}"
    );
    let message = e.to_string();
    assert!(
        message.contains(info.frames[1]) && message.contains("1e39"),
        "{message}"
    );
    // and so is a time 1e39 s after the first
    let mut late = dpend_run(0.1);
    let last = late.len() - 1;
    late.t[last] = 1e39;
    let e = mbs::gltf::document(info, &late, &GltfOptions::default()).unwrap_err();
    assert!(
        matches!(e, ExportError::BeyondSinglePrecision { output, .. } if output == last),
        "{e}"
    );
}

fn base64_decode(s: &str) -> Vec<u8> {
    let val = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    } as u32;
    let bytes = s.trim_end_matches('=').as_bytes();
    let mut out = Vec::new();
    for chunk in bytes.chunks(4) {
        let mut n = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            n |= val(c) << (18 - 6 * k);
        }
        for k in 0..chunk.len() - 1 {
            out.push((n >> (16 - 8 * k)) as u8);
        }
    }
    out
}

/// The values of an accessor of f32 (or u32, as f64) components, checked against its view.
fn read_accessor(root: &gltf_json::Root, bin: &[u8], a: &gltf_json::Accessor) -> Vec<f64> {
    use gltf_json::accessor::ComponentType;
    let view = &root.buffer_views[a.buffer_view.unwrap().value()];
    let start =
        view.byte_offset.map_or(0, |o| o.0 as usize) + a.byte_offset.map_or(0, |o| o.0 as usize);
    let n = a.type_.unwrap().multiplicity() * a.count.0 as usize;
    assert!(view.byte_stride.is_none());
    assert!(
        start + 4 * n <= view.byte_offset.map_or(0, |o| o.0 as usize) + view.byte_length.0 as usize,
        "the accessor overruns its view"
    );
    let kind = a.component_type.unwrap().0;
    (0..n)
        .map(|k| {
            let b: [u8; 4] = bin[start + 4 * k..start + 4 * k + 4].try_into().unwrap();
            match kind {
                ComponentType::F32 => f32::from_le_bytes(b) as f64,
                ComponentType::U32 => u32::from_le_bytes(b) as f64,
                other => panic!("unexpected component type {other:?}"),
            }
        })
        .collect()
}

#[test]
fn the_gltf_parses_back_consistent_and_samples_the_poses() {
    let (model, tr) = crane_run();
    let info = model.info();
    let dir = out_dir("gltf");
    let path = dir.join("crane.gltf");
    mbs::gltf::write_gltf(&path, info, &tr).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let root = gltf_json::Root::from_str(&text).expect("gltf-json reads it back");
    let mut problems = Vec::new();
    gltf_json::validation::Validate::validate(
        &root,
        &root,
        gltf_json::Path::new,
        &mut |path, e| problems.push(format!("{}: {e:?}", path())),
    );
    assert!(problems.is_empty(), "{problems:?}");
    assert_eq!(root.asset.version, "2.0");

    // one buffer, embedded, of the length it says
    assert_eq!(root.buffers.len(), 1);
    let uri = root.buffers[0].uri.as_deref().unwrap();
    let b64 = uri
        .strip_prefix("data:application/octet-stream;base64,")
        .expect("a data URI");
    let bin = base64_decode(b64);
    assert_eq!(bin.len() as u64, root.buffers[0].byte_length.0);
    for v in &root.buffer_views {
        let end = v.byte_offset.map_or(0, |o| o.0) + v.byte_length.0;
        assert!(end <= bin.len() as u64, "a view past the buffer");
    }
    // every accessor within its view, min and max those of its data, indices in range
    for a in &root.accessors {
        let values = read_accessor(&root, &bin, a);
        let m = a.type_.unwrap().multiplicity();
        if let (Some(min), Some(max)) = (&a.min, &a.max) {
            let (min, max) = (floats(min), floats(max));
            assert_eq!((min.len(), max.len()), (m, m));
            for c in 0..m {
                let col = values.iter().skip(c).step_by(m);
                let lo = col.clone().fold(f64::INFINITY, |x, &y| x.min(y));
                let hi = col.fold(f64::NEG_INFINITY, |x, &y| x.max(y));
                // written as f32 (the components' type), read back as f64
                assert_eq!(
                    (min[c] as f32, max[c] as f32),
                    (lo as f32, hi as f32),
                    "accessor min/max"
                );
            }
        }
    }
    for mesh in &root.meshes {
        for prim in &mesh.primitives {
            let pos = &root.accessors[prim.attributes
                [&gltf_json::validation::Checked::Valid(gltf_json::mesh::Semantic::Positions)]
                .value()];
            assert!(
                pos.min.is_some() && pos.max.is_some(),
                "POSITION needs min and max"
            );
            let idx = read_accessor(&root, &bin, &root.accessors[prim.indices.unwrap().value()]);
            assert!(
                idx.iter().all(|&i| (i as u64) < pos.count.0),
                "an index out of range"
            );
        }
    }

    // nodes: one per body or frame (named), the ground, the root turned to glTF's y up
    let names: Vec<_> = root
        .nodes
        .iter()
        .map(|n| n.name.clone().unwrap_or_default())
        .collect();
    for f in info.frames {
        assert!(names.iter().any(|n| n == f), "no node {f}");
    }
    assert!(names.iter().any(|n| n == "ground"));
    let scene = &root.scenes[root.scene.unwrap().value()];
    let top = &root.nodes[scene.nodes[0].value()];
    assert_eq!(top.name.as_deref(), Some("Crane"));
    assert_eq!(top.children.as_ref().unwrap().len(), info.frames.len() + 1);
    let r = top.rotation.unwrap().0;
    assert!((r[0] + std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-7 && r[1] == 0.0 && r[2] == 0.0);
    // meshes: the cart's box and cylinder, the rod's default box, the bob, the hook's line
    let mesh_of = |name: &str| {
        let node = root
            .nodes
            .iter()
            .find(|n| n.name.as_deref() == Some(name))
            .unwrap();
        &root.meshes[node.mesh.expect("a mesh").value()]
    };
    assert_eq!(mesh_of("cart").primitives.len(), 2);
    assert_eq!(mesh_of("rod").primitives.len(), 1);
    assert_eq!(mesh_of("bob").primitives.len(), 1);
    assert_eq!(mesh_of("ground").primitives.len(), 1);
    let line = &mesh_of("hook").primitives[0];
    assert_eq!(line.mode.unwrap(), gltf_json::mesh::Mode::Lines);
    assert_eq!(
        mesh_of("cart").primitives[0].mode.unwrap(),
        gltf_json::mesh::Mode::Triangles
    );
    let cart_box = read_accessor(
        &root,
        &bin,
        &root.accessors[mesh_of("cart").primitives[0].indices.unwrap().value()],
    );
    assert_eq!(cart_box.len(), 36, "a box is 12 triangles");
    let colour = root.materials[mesh_of("bob").primitives[0].material.unwrap().value()]
        .name
        .clone();
    assert_eq!(colour.as_deref(), Some("#cc3333"));

    // the animation: a translation and a rotation per body or frame, at every output
    assert_eq!(root.animations.len(), 1);
    let anim = &root.animations[0];
    assert_eq!(anim.samplers.len(), 2 * info.frames.len());
    assert_eq!(anim.channels.len(), 2 * info.frames.len());
    let n = tr.len();
    for ch in &anim.channels {
        let node = &root.nodes[ch.target.node.value()];
        let f = info.frame_index(node.name.as_deref().unwrap()).unwrap();
        let sampler = &anim.samplers[ch.sampler.value()];
        assert_eq!(
            sampler.interpolation.unwrap(),
            gltf_json::animation::Interpolation::Linear
        );
        let input = &root.accessors[sampler.input.value()];
        assert_eq!(input.count.0 as usize, n);
        let times = read_accessor(&root, &bin, input);
        for (a, b) in times.iter().zip(&tr.t) {
            assert!((a - (b - tr.t[0])).abs() < 1e-6);
        }
        let out = read_accessor(&root, &bin, &root.accessors[sampler.output.value()]);
        match ch.target.path.unwrap() {
            gltf_json::animation::Property::Translation => {
                assert_eq!(out.len(), 3 * n);
                for i in 0..n {
                    let p = tr.poses_at(i)[f].position;
                    for c in 0..3 {
                        assert_eq!(
                            out[3 * i + c],
                            p[c] as f32 as f64,
                            "translation of {} at output {i}",
                            info.frames[f]
                        );
                    }
                }
            }
            gltf_json::animation::Property::Rotation => {
                assert_eq!(out.len(), 4 * n);
                for i in 0..n {
                    let q = [0, 1, 2, 3].map(|c| out[4 * i + c]);
                    same_rotation(q, &tr.poses_at(i)[f], 1e-6);
                    if i > 0 {
                        let d: f64 = (0..4).map(|c| q[c] * out[4 * (i - 1) + c]).sum();
                        assert!(d > 0.0, "a sign flip between outputs");
                    }
                }
            }
            other => panic!("unexpected channel {other:?}"),
        }
    }
    // a planar model: no turned root
    let dp = dpend_run(0.5);
    let root = mbs::gltf::document(
        dpend::DoublePendulum::default().info(),
        &dp,
        &GltfOptions::default(),
    )
    .unwrap();
    let top = &root.nodes[root.scenes[0].nodes[0].value()];
    assert!(top.rotation.is_none());
}

// ---------- the page in a real browser, when one is installed ----------

fn browser() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    for name in [
        "chromium",
        "chromium-browser",
        "google-chrome",
        "google-chrome-stable",
    ] {
        for dir in std::env::split_paths(&path) {
            let p = dir.join(name);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    None
}

/// Runs the headless browser on `page` with `args`; (stdout, stderr), killed after 60 s.
fn headless(browser: &Path, profile: &Path, page: &Path, args: &[&str]) -> (String, String) {
    let mut cmd = Command::new(browser);
    cmd.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--disable-extensions",
        "--hide-scrollbars",
        "--enable-logging=stderr",
        "--v=0",
        "--window-size=900,650",
        "--virtual-time-budget=2000",
    ]);
    // a fresh profile: one left by a browser killed mid-run holds a lock the next one refuses
    let _ = std::fs::remove_dir_all(profile);
    cmd.arg(format!("--user-data-dir={}", profile.display()));
    cmd.args(args);
    cmd.arg(format!("file://{}", page.display()));
    let out_path = profile.with_extension("stdout");
    let err_path = profile.with_extension("stderr");
    cmd.stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap());
    let mut child = cmd.spawn().expect("the browser starts");
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the browser did not finish in 60 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    (
        std::fs::read_to_string(&out_path).unwrap_or_default(),
        std::fs::read_to_string(&err_path).unwrap_or_default(),
    )
}

/// Console messages of the page (Chromium logs them as `CONSOLE` lines with `--enable-logging`).
fn console_lines(stderr: &str) -> Vec<&str> {
    stderr.lines().filter(|l| l.contains("CONSOLE")).collect()
}

/// What the page wrote in `#mbs-status`: its text and attributes.
fn status(dom: &str) -> (String, String) {
    let k = dom.find("id=\"mbs-status\"").expect("the status element");
    let open = dom[..k].rfind('<').unwrap();
    let close = open + dom[open..].find("</output>").unwrap();
    let tag_end = open + dom[open..].find('>').unwrap();
    (
        dom[tag_end + 1..close].to_string(),
        dom[open..tag_end].to_string(),
    )
}

fn attribute(tag: &str, name: &str) -> f64 {
    let key = format!("{name}=\"");
    let k = tag
        .find(&key)
        .unwrap_or_else(|| panic!("no {name} in {tag}"))
        + key.len();
    tag[k..k + tag[k..].find('"').unwrap()].parse().unwrap()
}

/// Loads the page, checks it in the DOM and a screenshot; returns the screenshot's size.
fn check_in_browser(browser: &Path, dir: &Path, page: &Path, frames: usize) -> (u64, f64, f64) {
    let (dom, err) = headless(browser, &dir.join("profile-dom"), page, &["--dump-dom"]);
    assert!(
        console_lines(&err).is_empty(),
        "console messages: {:?}",
        console_lines(&err)
    );
    let (text, tag) = status(&dom);
    assert_eq!(
        text,
        format!("ready: {frames} frames"),
        "the page reported: {text}"
    );
    let painted = attribute(&tag, "data-painted");
    let colors = attribute(&tag, "data-colors");
    assert!(painted > 0.02, "the canvas is nearly empty: {painted}");
    assert!(colors >= 8.0, "the canvas has {colors} colours");
    let png = dir.join(format!(
        "{}.png",
        page.file_stem().unwrap().to_string_lossy()
    ));
    let shot = format!("--screenshot={}", png.display());
    let (_, err) = headless(browser, &dir.join("profile-shot"), page, &[&shot]);
    assert!(
        console_lines(&err).is_empty(),
        "console messages: {:?}",
        console_lines(&err)
    );
    let size = std::fs::metadata(&png).expect("a screenshot").len();
    (size, painted, colors)
}

/// Pauses, scrubs to the middle, switches the up axis, drags, zooms, resets, then writes
/// what the page shows into `#probe`.
const PROBE: &str = r#"<script>
setTimeout(function () {
  const $ = (id) => document.getElementById(id);
  const canvas = $("view"), out = [];
  $("play").click();
  $("scrub").value = 500;
  $("scrub").dispatchEvent(new Event("input"));
  out.push("paused at " + $("time").textContent);
  const before = $("up").value;
  $("up").value = before === "z" ? "y" : "z";
  $("up").dispatchEvent(new Event("change"));
  $("up").value = before;
  $("up").dispatchEvent(new Event("change"));
  out.push("up " + (before === "z" ? "y" : "z") + ", then " + before);
  // toDataURL, not getImageData: repeated readbacks draw a performance warning
  const a = canvas.toDataURL();
  const opts = { bubbles: true, clientX: 300, clientY: 300, pointerId: 1 };
  canvas.dispatchEvent(new PointerEvent("pointerdown", opts));
  canvas.dispatchEvent(new PointerEvent("pointermove", Object.assign({}, opts, { clientX: 380, clientY: 330 })));
  canvas.dispatchEvent(new PointerEvent("pointerup", opts));
  canvas.dispatchEvent(new WheelEvent("wheel", { deltaY: 200, bubbles: true, cancelable: true }));
  out.push("picture changed by turning: " + (canvas.toDataURL() !== a));
  canvas.dispatchEvent(new MouseEvent("dblclick", { bubbles: true }));
  out.push($("mbs-status").textContent);
  const pre = document.createElement("pre");
  pre.id = "probe";
  pre.textContent = out.join("\n");
  document.body.appendChild(pre);
}, 300);
</script>
</body>"#;

/// Whether a missing browser fails the test rather than being reported: under CI (`CI` set to
/// anything but `false` or `0`, as CI services do) or with `MBS_REQUIRE_BROWSER=1` (`.ci/run`
/// sets it); `MBS_REQUIRE_BROWSER=0` lets a CI machine without a browser pass it on purpose.
fn browser_required(ci: Option<&str>, require: Option<&str>) -> bool {
    match require {
        Some("1") => true,
        Some("0") => false,
        _ => ci.is_some_and(|v| !matches!(v.trim(), "" | "0" | "false")),
    }
}

#[test]
fn a_missing_browser_fails_under_ci() {
    assert!(browser_required(Some("true"), None));
    assert!(browser_required(Some("1"), None));
    assert!(browser_required(None, Some("1")));
    assert!(browser_required(Some("false"), Some("1")));
    assert!(!browser_required(None, None));
    assert!(!browser_required(Some("false"), None));
    assert!(!browser_required(Some(""), None));
    assert!(!browser_required(Some("true"), Some("0")));
}

#[test]
fn the_page_runs_in_a_headless_browser() {
    let Some(browser) = browser() else {
        let (ci, require) = (
            std::env::var("CI").ok(),
            std::env::var("MBS_REQUIRE_BROWSER").ok(),
        );
        assert!(
            !browser_required(ci.as_deref(), require.as_deref()),
            "no chromium, chromium-browser, google-chrome or google-chrome-stable on PATH, and a \
             browser is required here (CI = {ci:?}, MBS_REQUIRE_BROWSER = {require:?}): install \
             Debian's `chromium`, or set MBS_REQUIRE_BROWSER=0 to skip the check knowingly"
        );
        let msg = "\n*** NO BROWSER: neither chromium, chromium-browser nor google-chrome is on PATH, so \
                   the page was NOT loaded in a browser (install Debian's `chromium` to run this \
                   check); everything else about the page is checked by the other tests ***\n";
        println!("{msg}");
        // straight to the terminal too: the harness keeps a passing test's println! to itself
        let _ = std::io::Write::write_all(&mut std::io::stderr(), msg.as_bytes());
        return;
    };
    let dir = out_dir("browser");
    // the check catches a script error (so that its silence means something)
    let broken = dir.join("broken.html");
    std::fs::write(
        &broken,
        "<!DOCTYPE html><html><body><script>undefined_function();</script></body></html>",
    )
    .unwrap();
    let (_, err) = headless(
        &browser,
        &dir.join("profile-broken"),
        &broken,
        &["--dump-dom"],
    );
    assert!(
        console_lines(&err)
            .iter()
            .any(|l| l.contains("undefined_function")),
        "a script error did not show in the browser's log: {err}"
    );
    // a blank page of the same size and colour, for the screenshots
    let blank = dir.join("blank.html");
    std::fs::write(
        &blank,
        "<!DOCTYPE html><html><body style=\"margin:0;background:#f3f4f6\"></body></html>",
    )
    .unwrap();
    let blank_png = dir.join("blank.png");
    headless(
        &browser,
        &dir.join("profile-blank"),
        &blank,
        &[&format!("--screenshot={}", blank_png.display())],
    );
    let blank_size = std::fs::metadata(&blank_png)
        .expect("a screenshot of the blank page")
        .len();

    let (model, tr) = crane_run();
    let page = dir.join("crane.html");
    mbs::anim::write_html(&page, model.info(), &tr).unwrap();
    let (size, painted, colors) = check_in_browser(&browser, &dir, &page, tr.len());
    println!(
        "crane: screenshot {size} bytes (blank page {blank_size}), {painted} of the canvas painted, {colors} colours"
    );
    assert!(
        size > 3 * blank_size,
        "the screenshot ({size} bytes) is hardly larger than a blank page's ({blank_size})"
    );

    // the controls, driven by a script added to a copy of the page: no error, and they act
    let probe = dir.join("crane-probe.html");
    let html = std::fs::read_to_string(&page).unwrap();
    std::fs::write(&probe, html.replace("</body>", PROBE)).unwrap();
    let (dom, err) = headless(
        &browser,
        &dir.join("profile-probe"),
        &probe,
        &["--dump-dom"],
    );
    assert!(
        console_lines(&err).is_empty(),
        "console messages: {:?}",
        console_lines(&err)
    );
    let k = dom.find("<pre id=\"probe\">").expect("the probe ran") + "<pre id=\"probe\">".len();
    let report = &dom[k..k + dom[k..].find("</pre>").unwrap()];
    println!("controls: {report}");
    let lines: Vec<&str> = report.lines().collect();
    assert_eq!(lines[0], "paused at t = 0.500 s / 1.000 s", "{report}");
    assert_eq!(lines[1], "up y, then z");
    assert_eq!(lines[2], "picture changed by turning: true");
    assert!(lines[3].starts_with("ready: "), "{report}");

    let dp = dpend_run(2.0);
    let page = dir.join("dpend.html");
    mbs::anim::write_html(&page, dpend::DoublePendulum::default().info(), &dp).unwrap();
    let html_size = std::fs::metadata(&page).unwrap().len();
    let (size, painted, colors) = check_in_browser(&browser, &dir, &page, dp.len());
    println!(
        "dpend, 2 s: {} outputs, page {html_size} bytes; screenshot {size} bytes, {painted} painted, {colors} colours",
        dp.len()
    );
    assert!(size > 3 * blank_size);
    println!("pages and screenshots in {}", dir.display());
}
