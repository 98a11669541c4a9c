//! The motion as one self-contained HTML page: open it in a browser, offline, to watch the
//! bodies move. The page carries its own small renderer (a 2D canvas, perspective
//! projection, polygons painted back to front, flat shading), the shapes of every body and
//! the recorded poses as JSON; it loads nothing from anywhere.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # mbs::multibody! { model Swing { dof a = 0.5; body bar { mass = 1.0; inertia = (0.1, 0.01, 0.1); }
//! #   TOG[bar] = Trotz(a) * Tdisp(0, -0.5, 0); shape bar: box(0.05, 1.0, 0.05); gravity(0, -9.81, 0); } }
//! use mbs::Model;
//! let model = Swing::default();
//! let info = model.info();
//! let options = mbs::Options { frames: true, ..mbs::Options::adaptive(2.0, 1e-6) };
//! let (trajectory, _) = mbs::simulate(model, mbs::Scheme::Dopri5, options)?;
//! mbs::anim::write_html("swing.html".as_ref(), info, &trajectory)?;
//! # Ok(()) }
//! ```
//!
//! Each body is drawn with its shapes (`shape` statements, [`ModelInfo::shapes`]): a body
//! that declares none is drawn as its equivalent box, a frame that declares none is not
//! drawn. The page has a ground grid below the lowest point of the motion, play/pause
//! (space), speed, a scrub bar, the time, and an orbit camera: drag to turn, wheel to zoom,
//! double-click to reset. Poses between outputs are interpolated (positions linearly,
//! rotations by normalised quaternion interpolation).
//!
//! For tests the page sets `window.mbsFrameCount` (the number of poses it plays) and, once it
//! has drawn, the element `#mbs-status` to `ready: N frames` with the share of the canvas
//! painted (`data-painted`, sampled) and the number of colours seen (`data-colors`); an error
//! in the script shows there as `error: …`.

use crate::export::{Frames, tessellate};
use crate::model::ModelInfo;
use crate::trajectory::Trajectory;
use std::fmt::Write;
use std::path::Path;

pub use crate::export::{ExportError, Up, palette};

/// Options of [`write_html_with`].
#[derive(Clone, Debug)]
pub struct AnimOptions {
    /// which world axis points up at first (the page can switch)
    pub up: Up,
    /// the page's title (default: the model's name)
    pub title: Option<String>,
    /// at most this many poses are embedded: more outputs are thinned evenly, keeping the
    /// first and the last (default 20 000)
    pub max_frames: usize,
}

impl Default for AnimOptions {
    fn default() -> Self {
        AnimOptions {
            up: Up::Auto,
            title: None,
            max_frames: 20_000,
        }
    }
}

/// Writes the animation of `trajectory` (recorded with `Options::frames = true`) of the model
/// described by `info` as one HTML file at `path`.
pub fn write_html(
    path: &Path,
    info: &ModelInfo,
    trajectory: &Trajectory,
) -> Result<(), ExportError> {
    write_html_with(path, info, trajectory, &AnimOptions::default())
}

/// [`write_html`] with options.
pub fn write_html_with(
    path: &Path,
    info: &ModelInfo,
    trajectory: &Trajectory,
    options: &AnimOptions,
) -> Result<(), ExportError> {
    let page = html(info, trajectory, options)?;
    std::fs::write(path, page).map_err(|source| ExportError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// A number with `decimals` decimals at most, without trailing zeros.
fn num(out: &mut String, x: f64, decimals: usize) {
    let start = out.len();
    let _ = write!(out, "{x:.decimals$}");
    if out[start..].contains('.') {
        while out.ends_with('0') {
            out.pop();
        }
        if out.ends_with('.') {
            out.pop();
        }
    }
    if &out[start..] == "-0" {
        out.truncate(start);
        out.push('0');
    }
}

/// A JSON string (names are identifiers, but be safe).
fn json_string(out: &mut String, s: &str) {
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '<' => out.push_str("\\u003c"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
}

/// The data the page plays, as JSON: `{"model", "frames", "up", "shapes": [{"f", "c", "v",
/// "q", "l"}], "t", "p"}` with `p` the poses, 7 numbers per frame per output: the rotation
/// as a quaternion (x, y, z, w), then the position.
pub fn data_json(
    info: &ModelInfo,
    trajectory: &Trajectory,
    options: &AnimOptions,
) -> Result<String, ExportError> {
    let mut frames = Frames::new(info, trajectory)?;
    let up = options.up.resolve(&frames);
    frames.thin(options.max_frames);
    let tess: Vec<_> = info.shapes.iter().map(tessellate).collect();
    // positions to a millionth of the largest coordinate
    let mut scale = 1e-9f64;
    for k in 0..frames.len() {
        for p in frames.pose(k) {
            scale = p.position.iter().fold(scale, |s, x| s.max(x.abs()));
        }
    }
    for t in &tess {
        for p in &t.positions {
            scale = p.iter().fold(scale, |s, x| s.max(x.abs()));
        }
    }
    let decimals = (6 - scale.log10().floor() as i64).clamp(0, 15) as usize;
    let mut s = String::new();
    s.push_str("{\"model\":");
    json_string(&mut s, info.name);
    s.push_str(",\"frames\":[");
    for (i, f) in info.frames.iter().enumerate() {
        if i > 0 {
            s.push(',');
        }
        json_string(&mut s, f);
    }
    let _ = write!(
        s,
        "],\"up\":\"{}\",\"decimals\":{decimals},\"shapes\":[",
        if up == Up::Z { "z" } else { "y" }
    );
    for (k, (shape, t)) in info.shapes.iter().zip(&tess).enumerate() {
        if k > 0 {
            s.push(',');
        }
        let c = palette(shape);
        let _ = write!(
            s,
            "{{\"f\":{},\"c\":\"#{:02x}{:02x}{:02x}\",\"v\":[",
            shape.frame.map_or(-1, |i| i as i64),
            c[0],
            c[1],
            c[2]
        );
        for (i, x) in t.positions.iter().flatten().enumerate() {
            if i > 0 {
                s.push(',');
            }
            num(&mut s, *x, decimals);
        }
        s.push_str("],\"q\":[");
        for (i, f) in t.faces.iter().enumerate() {
            if i > 0 {
                s.push(',');
            }
            let list: Vec<String> = f.iter().map(|v| v.to_string()).collect();
            let _ = write!(s, "[{}]", list.join(","));
        }
        s.push_str("],\"l\":[");
        for (i, l) in t.lines.iter().enumerate() {
            if i > 0 {
                s.push(',');
            }
            let _ = write!(s, "[{},{}]", l[0], l[1]);
        }
        s.push_str("]}");
    }
    s.push_str("],\"t\":[");
    for k in 0..frames.len() {
        if k > 0 {
            s.push(',');
        }
        let _ = write!(s, "{}", frames.time(k));
    }
    s.push_str("],\"p\":[");
    // each quaternion of the sign nearest the previous one, so that interpolation between
    // outputs takes the short way
    let mut previous = vec![[0.0, 0.0, 0.0, 1.0]; info.frames.len()];
    for k in 0..frames.len() {
        for (i, p) in frames.pose(k).iter().enumerate() {
            let mut q = p.quaternion();
            if (0..4).map(|c| q[c] * previous[i][c]).sum::<f64>() < 0.0 {
                q = q.map(|c| -c);
            }
            previous[i] = q;
            for (c, x) in q.iter().enumerate() {
                if k + i + c > 0 {
                    s.push(',');
                }
                num(&mut s, *x, 7);
            }
            for x in p.position {
                s.push(',');
                num(&mut s, x, decimals);
            }
        }
    }
    s.push_str("]}");
    Ok(s)
}

/// The page of [`write_html`].
pub fn html(
    info: &ModelInfo,
    trajectory: &Trajectory,
    options: &AnimOptions,
) -> Result<String, ExportError> {
    let data = data_json(info, trajectory, options)?;
    let title = options.title.clone().unwrap_or_else(|| {
        if info.scene.is_empty() {
            info.name.to_string()
        } else {
            format!("{} ({})", info.name, info.scene)
        }
    });
    let escape = |s: &str| {
        s.replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;")
            .replace('"', "&quot;")
    };
    Ok(PAGE
        .replace("{{TITLE}}", &escape(&title))
        .replace("{{SCRIPT}}", SCRIPT)
        .replace("{{DATA}}", &data.replace("</", "<\\/")))
}

const PAGE: &str = r##"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="mbs::anim">
<link rel="icon" href="data:,">
<title>{{TITLE}}</title>
<style>
html, body { margin: 0; height: 100%; background: #f3f4f6; color: #222; font: 14px system-ui, sans-serif; overflow: hidden; }
#view { display: block; width: 100%; height: calc(100% - 46px); touch-action: none; cursor: grab; }
#view.drag { cursor: grabbing; }
#bar { height: 46px; box-sizing: border-box; display: flex; align-items: center; gap: 12px; padding: 0 12px; background: #fff; border-top: 1px solid #d8dade; }
#scrub { flex: 1; min-width: 80px; }
#time { font-variant-numeric: tabular-nums; white-space: nowrap; min-width: 11em; }
#play { min-width: 5em; }
button, select { font: inherit; }
#title { position: absolute; top: 8px; left: 12px; pointer-events: none; }
#title b { font-size: 15px; }
#title span { color: #666; font-size: 12px; }
#mbs-status { color: #888; font-size: 12px; white-space: nowrap; }
</style>
</head>
<body>
<canvas id="view"></canvas>
<div id="title"><b>{{TITLE}}</b><br><span>drag to turn · wheel to zoom · double-click to reset · space to play or pause</span></div>
<div id="bar">
<button id="play" type="button">Pause</button>
<label>speed <select id="speed"><option value="0.1">0.1×</option><option value="0.25">0.25×</option><option value="0.5">0.5×</option><option value="1" selected>1×</option><option value="2">2×</option><option value="4">4×</option></select></label>
<input id="scrub" type="range" min="0" max="1000" step="1" value="0" aria-label="time">
<span id="time">t = 0 s</span>
<label>up <select id="up"><option value="y">y</option><option value="z">z</option></select></label>
<output id="mbs-status">loading</output>
</div>
<script type="application/json" id="mbs-data">{{DATA}}</script>
<script>{{SCRIPT}}</script>
</body>
</html>
"##;

/// The renderer: plain JavaScript, no library.
const SCRIPT: &str = r##"
"use strict";
(function () {
  const status = document.getElementById("mbs-status");
  window.addEventListener("error", function (e) { status.textContent = "error: " + e.message; });
  const D = JSON.parse(document.getElementById("mbs-data").textContent);
  const NF = D.frames.length, N = D.t.length;
  window.mbsFrameCount = N;
  const t0 = D.t[0], t1 = D.t[N - 1];
  const canvas = document.getElementById("view"), ctx = canvas.getContext("2d");
  const playBtn = document.getElementById("play"), speedSel = document.getElementById("speed");
  const scrub = document.getElementById("scrub"), timeEl = document.getElementById("time");
  const upSel = document.getElementById("up");
  const BG = [243, 244, 246];

  // vectors
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const norm = (a) => { const n = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / n, a[1] / n, a[2] / n]; };
  const hex = (c) => [1, 3, 5].map((i) => parseInt(c.substr(i, 2), 16));

  // the world of the model → the view's world, z up
  let up = D.up;
  const toView = (p) => (up === "z" ? p : [p[0], -p[2], p[1]]);

  // poses: quaternion (x, y, z, w) and position, 7 numbers per frame per output
  function rotation(q) {
    const [x, y, z, w] = q;
    return [
      [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
      [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
      [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ];
  }
  function posesAt(t) {
    let lo = 0, hi = N - 1;
    if (t <= D.t[0]) hi = 0;
    else if (t >= D.t[N - 1]) lo = hi = N - 1;
    else {
      while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (D.t[mid] <= t) lo = mid; else hi = mid; }
    }
    const a = lo === hi ? 0 : (t - D.t[lo]) / (D.t[hi] - D.t[lo]);
    const out = [];
    for (let i = 0; i < NF; i++) {
      const p = (lo * NF + i) * 7, r = (hi * NF + i) * 7;
      const q = [0, 1, 2, 3].map((c) => (1 - a) * D.p[p + c] + a * D.p[r + c]);
      const n = Math.hypot(q[0], q[1], q[2], q[3]) || 1;
      out.push({
        R: rotation(q.map((c) => c / n)),
        x: [4, 5, 6].map((c) => (1 - a) * D.p[p + c] + a * D.p[r + c]),
      });
    }
    return out;
  }
  const apply = (pose, v) => {
    if (!pose) return v;
    const R = pose.R, x = pose.x;
    return [0, 1, 2].map((i) => x[i] + R[i][0] * v[0] + R[i][1] * v[1] + R[i][2] * v[2]);
  };
  const vertex = (s, k) => [s.v[3 * k], s.v[3 * k + 1], s.v[3 * k + 2]];

  // long thin quads (a slender box, a cylinder's side) cut into pieces not much longer than
  // wide, so that painting back to front by mean depth also works where bodies meet
  function refine(s) {
    const V = s.v.slice(), faces = [];
    const at = (k) => [V[3 * k], V[3 * k + 1], V[3 * k + 2]];
    for (const f of s.q) {
      if (f.length !== 4) { faces.push(f); continue; }
      const [a, b, c, d] = f.map(at);
      const la = Math.hypot(...sub(b, a)), lb = Math.hypot(...sub(d, a));
      const short = Math.max(Math.min(la, lb), 1e-12);
      const nu = Math.min(16, Math.ceil(la / (2 * short) - 1e-9)), nv = Math.min(16, Math.ceil(lb / (2 * short) - 1e-9));
      if (nu * nv <= 1) { faces.push(f); continue; }
      const grid = [];
      for (let i = 0; i <= nu; i++) {
        const row = [];
        for (let j = 0; j <= nv; j++) {
          const u = i / nu, v = j / nv;
          for (let k = 0; k < 3; k++) V.push((1 - u) * (1 - v) * a[k] + u * (1 - v) * b[k] + u * v * c[k] + (1 - u) * v * d[k]);
          row.push(V.length / 3 - 1);
        }
        grid.push(row);
      }
      for (let i = 0; i < nu; i++) for (let j = 0; j < nv; j++) faces.push([grid[i][j], grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]]);
    }
    s.v = V; s.q = faces;
  }
  D.shapes.forEach(refine);

  const FOV = 45 * Math.PI / 180;

  // extent of the motion (sampled), the ground and its grid, the camera's home
  let lo, hi, ground, grid, home;
  function measure() {
    lo = [Infinity, Infinity, Infinity]; hi = [-Infinity, -Infinity, -Infinity];
    const grow = (p) => { for (let c = 0; c < 3; c++) { lo[c] = Math.min(lo[c], p[c]); hi[c] = Math.max(hi[c], p[c]); } };
    grow(toView([0, 0, 0]));
    const step = Math.max(1, Math.floor(N / 200));
    for (let k = 0; k < N; k += step) {
      const poses = posesAt(D.t[k]);
      for (const s of D.shapes) {
        const pose = s.f >= 0 ? poses[s.f] : null;
        for (let j = 0; j < s.v.length / 3; j++) grow(toView(apply(pose, vertex(s, j))));
      }
      for (const p of poses) grow(toView(p.x));
    }
    const size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-6);
    ground = Math.min(0, lo[2]);
    const raw = size / 8, p10 = Math.pow(10, Math.floor(Math.log10(raw)));
    const spacing = [1, 2, 5, 10].map((m) => m * p10).find((s) => s >= raw);
    const cx = Math.round((lo[0] + hi[0]) / 2 / spacing) * spacing;
    const cy = Math.round((lo[1] + hi[1]) / 2 / spacing) * spacing;
    const half = Math.ceil((0.75 * Math.max(hi[0] - lo[0], hi[1] - lo[1]) + size * 0.25) / spacing) * spacing;
    grid = [];
    for (let u = -half; u <= half + 1e-9 * half; u += spacing) {
      grid.push([[cx + u, cy - half, ground], [cx + u, cy + half, ground]]);
      grid.push([[cx - half, cy + u, ground], [cx + half, cy + u, ground]]);
    }
    const center = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (Math.max(lo[2], ground) + hi[2]) / 2];
    const radius = 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
    home = { target: center, dist: radius / Math.sin(0.5 * FOV) * 1.15, yaw: up === "z" ? -1.05 : -Math.PI / 2, pitch: up === "z" ? 0.42 : 0.2 };
  }
  let cam;

  // time
  let t = t0, playing = N > 1, speed = 1, last = null;
  function setTime(v) {
    t = Math.min(Math.max(v, t0), t1);
    scrub.value = t1 > t0 ? Math.round(1000 * (t - t0) / (t1 - t0)) : 0;
    timeEl.textContent = "t = " + t.toFixed(3) + " s / " + t1.toFixed(3) + " s";
  }

  // drawing
  function draw() {
    const dpr = window.devicePixelRatio || 1;
    const W = Math.max(1, Math.round(canvas.clientWidth * dpr)), H = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== W || canvas.height !== H) { canvas.width = W; canvas.height = H; }
    ctx.fillStyle = "rgb(" + BG.join(",") + ")";
    ctx.fillRect(0, 0, W, H);
    const cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch);
    const back = [cp * Math.cos(cam.yaw), cp * Math.sin(cam.yaw), sp];
    const eye = cam.target.map((c, i) => c + cam.dist * back[i]);
    const fwd = back.map((c) => -c);
    const right = norm(cross(fwd, [0, 0, 1])), camUp = cross(right, fwd);
    const light = norm([0, 1, 2].map((i) => -fwd[i] + 0.6 * camUp[i] - 0.35 * right[i]));
    const F = 0.5 * H / Math.tan(0.5 * FOV), near = 1e-3 * cam.dist;
    const view = (p) => { const d = sub(p, eye); return [dot(d, right), dot(d, camUp), dot(d, fwd)]; };
    const screen = (v) => [0.5 * W + F * v[0] / v[2], 0.5 * H - F * v[1] / v[2]];
    const items = [];
    // a segment on the screen, clipped at the near plane (null: behind the eye)
    function clip(a, b) {
      let va = view(a), vb = view(b);
      if (va[2] < near && vb[2] < near) return null;
      if (va[2] < near || vb[2] < near) {
        const s = (near - va[2]) / (vb[2] - va[2]);
        const m = [0, 1, 2].map((i) => va[i] + s * (vb[i] - va[i]));
        if (va[2] < near) va = m; else vb = m;
      }
      return { z: 0.5 * (va[2] + vb[2]), line: [screen(va), screen(vb)] };
    }
    function segment(a, b, color, width) {
      const it = clip(a, b);
      if (it) { it.color = color; it.width = width; items.push(it); }
    }
    const poses = posesAt(t);
    for (const s of D.shapes) {
      const pose = s.f >= 0 ? poses[s.f] : null;
      const base = s.rgb || (s.rgb = hex(s.c));
      const pts = [];
      for (let j = 0; j < s.v.length / 3; j++) pts.push(toView(apply(pose, vertex(s, j))));
      for (const l of s.l) segment(pts[l[0]], pts[l[1]], "rgb(" + base.join(",") + ")", 3 * dpr);
      for (const f of s.q) {
        const P = f.map((k) => pts[k]);
        // Newell's normal; skip faces turned away from the eye
        let n = [0, 0, 0];
        for (let i = 0; i < P.length; i++) {
          const a = P[i], b = P[(i + 1) % P.length];
          n[0] += (a[1] - b[1]) * (a[2] + b[2]); n[1] += (a[2] - b[2]) * (a[0] + b[0]); n[2] += (a[0] - b[0]) * (a[1] + b[1]);
        }
        n = norm(n);
        if (dot(n, sub(P[0], eye)) >= 0) continue;
        const V = P.map(view);
        if (V.some((v) => v[2] < near)) continue;
        const shade = 0.35 + 0.65 * Math.max(0, dot(n, light));
        const rgb = base.map((c) => Math.round(Math.min(255, c * shade)));
        items.push({ z: V.reduce((z, v) => z + v[2], 0) / V.length, poly: V.map(screen), color: "rgb(" + rgb.join(",") + ")" });
      }
    }
    // world axes at the origin
    const L = 0.08 * Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    const o = toView([0, 0, 0]);
    [["#d33", [L, 0, 0]], ["#3a3", [0, L, 0]], ["#33d", [0, 0, L]]].forEach(([c, a]) => segment(o, toView(a), c, 2 * dpr));
    items.sort((a, b) => b.z - a.z);
    const above = eye[2] >= ground;
    const drawGrid = () => {
      ctx.lineWidth = dpr;
      ctx.strokeStyle = "rgba(110, 115, 125, 0.45)";
      for (const g of grid) {
        const it = clip(g[0], g[1]);
        if (!it) continue;
        ctx.beginPath(); ctx.moveTo(it.line[0][0], it.line[0][1]); ctx.lineTo(it.line[1][0], it.line[1][1]); ctx.stroke();
      }
    };
    if (above) drawGrid();
    ctx.lineJoin = "round";
    for (const it of items) {
      ctx.beginPath();
      if (it.poly) {
        ctx.moveTo(it.poly[0][0], it.poly[0][1]);
        for (let i = 1; i < it.poly.length; i++) ctx.lineTo(it.poly[i][0], it.poly[i][1]);
        ctx.closePath();
        ctx.fillStyle = it.color; ctx.fill();
        ctx.strokeStyle = it.color; ctx.lineWidth = 0.75 * dpr; ctx.stroke();
      } else {
        ctx.moveTo(it.line[0][0], it.line[0][1]); ctx.lineTo(it.line[1][0], it.line[1][1]);
        ctx.strokeStyle = it.color; ctx.lineWidth = it.width; ctx.lineCap = "round"; ctx.stroke();
      }
    }
    if (!above) drawGrid();
  }

  // what the page shows, for tests: the share of the canvas painted and the colours seen
  function report() {
    const W = canvas.width, H = canvas.height;
    const img = ctx.getImageData(0, 0, W, H).data;
    let painted = 0, seen = new Set(), total = 0;
    for (let y = 0; y < H; y += Math.max(1, H >> 6)) {
      for (let x = 0; x < W; x += Math.max(1, W >> 6)) {
        const i = 4 * (y * W + x);
        total++;
        if (img[i] !== BG[0] || img[i + 1] !== BG[1] || img[i + 2] !== BG[2]) painted++;
        seen.add((img[i] << 16) | (img[i + 1] << 8) | img[i + 2]);
      }
    }
    status.dataset.painted = (painted / total).toFixed(3);
    status.dataset.colors = String(seen.size);
    status.textContent = "ready: " + N + " frames";
  }

  function frame(now) {
    if (playing && last !== null) {
      let next = t + speed * (now - last) / 1000;
      if (next > t1) next = t0 + (next - t1) % Math.max(t1 - t0, 1e-9);
      setTime(next);
    }
    last = now;
    draw();
    requestAnimationFrame(frame);
  }

  // controls
  function setPlaying(p) { playing = p && N > 1; playBtn.textContent = playing ? "Pause" : "Play"; last = null; }
  playBtn.addEventListener("click", () => setPlaying(!playing));
  speedSel.addEventListener("change", () => { speed = parseFloat(speedSel.value); });
  scrub.addEventListener("input", () => { setTime(t0 + (t1 - t0) * scrub.value / 1000); draw(); });
  upSel.addEventListener("change", () => { up = upSel.value; measure(); cam = Object.assign({}, home); draw(); });
  window.addEventListener("keydown", (e) => { if (e.code === "Space" && e.target.tagName !== "SELECT") { e.preventDefault(); setPlaying(!playing); } });
  let drag = null;
  canvas.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); canvas.classList.add("drag"); });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag) return;
    cam.yaw -= 0.008 * (e.clientX - drag[0]);
    cam.pitch = Math.max(-1.5, Math.min(1.5, cam.pitch + 0.008 * (e.clientY - drag[1])));
    drag = [e.clientX, e.clientY];
    if (!playing) draw();
  });
  const release = () => { drag = null; canvas.classList.remove("drag"); };
  canvas.addEventListener("pointerup", release);
  canvas.addEventListener("pointercancel", release);
  canvas.addEventListener("wheel", (e) => { e.preventDefault(); cam.dist *= Math.exp(0.0015 * e.deltaY); if (!playing) draw(); }, { passive: false });
  canvas.addEventListener("dblclick", () => { cam = Object.assign({}, home); if (!playing) draw(); });
  window.addEventListener("resize", () => draw());

  upSel.value = up;
  measure();
  cam = Object.assign({}, home);
  setPlaying(playing);
  setTime(t0);
  draw();
  report();
  requestAnimationFrame(frame);
})();
"##;
