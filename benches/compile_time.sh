#!/usr/bin/env bash
# Compile time and peak memory of one model in a crate of its own, dependencies built first
# and not timed: release builds of a 24-joint spatial arm, a 32-bar planar chain, the
# hexapod with exact tangents, as code and as a table (its forward dynamics called, then a
# program that runs it with Radau5) and a 200-bar chain, then a debug build of the arm, and the arm with the batch
# functions of `option batch;` (its program calling them, and a program running an ensemble
# of it and nothing else).
#
#   benches/compile_time.sh            # all cases
#   benches/compile_time.sh chain32    # one case (arm24, chain32, hexapod, hexapod-radau,
#                                      # hexapod-code, hexapod-table, hexapod-table-radau:
#                                      # the hexapod with `option tangents = code;` or
#                                      # `= table;`, tangent-forms: Radau5 runs of both
#                                      # alternated, chain200, arm24-dev, arm24-batch: the arm with
#                                      # `option batch;`, arm24-ensemble: the same, its
#                                      # program running an ensemble and nothing else, which
#                                      # compiles the batch code's two instances)
#   benches/compile_time.sh --generator-unoptimised [cases]
#
# The model crate's Cargo.toml has the profile lines the README recommends: the generator
# (`mbs-symbolic`, which the proc-macro runs) optimised. `--generator-unoptimised` leaves them
# out and measures Cargo's default, which builds proc-macros and their dependencies at
# opt-level 0.
#
# Each timed build compiles the model crate from scratch (its artifacts cleaned, no
# incremental cache); the peak memory is the largest resident set of the build's processes
# (GNU time's %M, which covers the compiler and the proc-macro it runs).
set -euo pipefail
optimised=1
if [ "${1:-}" = --generator-unoptimised ]; then
    optimised=0
    shift
fi
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/src"
cat > "$dir/Cargo.toml" <<TOML
[package]
name = "one_model"
version = "0.0.0"
edition = "2024"
[dependencies]
mbs = { path = "$root" }
[workspace]
TOML
if [ "$optimised" = 1 ]; then
    cat >> "$dir/Cargo.toml" <<TOML
[profile.release.package.mbs-symbolic]
opt-level = 3
[profile.dev.package.mbs-symbolic]
opt-level = 3
TOML
fi

# the shapes of the scaling benchmark (`chain!`, `arm!`), one model named `Model`
shapes="$root/benches/scaling/shapes.rs"
chain() { # n bars
    cat "$shapes"
    echo "chain!(Model, $1);"
}
arm() { # n joints, n even; then options of the language
    cat "$shapes"
    local n=$1
    shift
    echo "arm!(Model, $n, $((n / 2 - 1)), $((n - 1)), $((n - 2))${*:+, $*});"
}

hexapod() { # the hexapod of models/src with `option tangents;` (or `option tangents = $1;`)
    # before its closing braces
    local option="tangents${1:+ = $1}"
    sed "s/^    }\$/        option $option;\n    }/" "$root/models/src/hexapod.rs"
    echo 'pub type Model = Hexapod;'
}

# the batch forward dynamics of one model in every lane (lane by lane without `option
# batch;`), which `main` calls beside the one-state forward dynamics
x4_call() {
    cat <<'RS'
pub fn batch(m: &Model) -> Option<f64> {
    use mbs::{F64x4, Model as _};
    let n = <Model as mbs::Model>::NQ;
    let (q4, z4) = (vec![F64x4::splat(0.1); n], vec![F64x4::ZERO; n]);
    let (mut a4, mut p4) = (z4.clone(), z4.clone());
    let u4 = vec![F64x4::ZERO; <Model as mbs::Model>::NU];
    m.forward_dynamics_x4(F64x4::ZERO, &q4, &z4, &u4, &mut a4, &mut p4);
    Some(a4[0].lane(0))
}
RS
}

# what `main` does besides forward dynamics: the batch call and nothing else, or
# (hexapod-radau, hexapod-table-radau) also Radau5 runs of the standing hexapod with its
# tangents, so that every function a run calls is compiled, timed: what the tangents' form
# costs at run time
no_run() {
    x4_call
    echo 'pub fn run() {}'
}
# a Radau5 run of 1 s of a standing hexapod: its time in ms and its steps
radau_timed() {
    cat <<'RS'
fn radau<M: mbs::Model + 'static>(m: M) -> (f64, usize) {
    let mut options = mbs::Options::default();
    options.t_end = 1.0;
    let start = std::time::Instant::now();
    let (_, stats) = mbs::simulate(m, mbs::Scheme::Radau5, options)
        .expect("the standing hexapod's run");
    (start.elapsed().as_secs_f64() * 1e3, stats.steps)
}
RS
}
radau_run() {
    x4_call
    radau_timed
    cat <<'RS'
pub fn run() {
    // the fastest of three runs: what the form of the tangents costs at run time
    let mut fastest = f64::INFINITY;
    let mut steps = 0;
    for _ in 0..3 {
        let (ms, n) = radau(HexapodStanding::default());
        fastest = fastest.min(ms);
        steps = n;
    }
    println!("Radau5, standing hexapod, 1 s: {steps} steps in {fastest:.1} ms (fastest of 3)");
}
RS
}

# (tangent-forms) the standing hexapod twice, its tangents as code and as a table, each form's
# Radau5 run of 1 s alternated with the other's: what the table costs at run time, measured in
# one program (its build time is that of both models)
tangent_forms() {
    echo 'pub mod code {'
    hexapod code
    echo '}'
    echo 'pub mod table {'
    hexapod table
    echo '}'
    echo 'pub type Model = code::Hexapod;'
    echo 'pub fn batch(_: &Model) -> Option<f64> { None }'
    radau_timed
    cat <<'RS'
pub fn run() {
    let mut ratios = Vec::new();
    for pair in 0..15 {
        let code = radau(code::HexapodStanding::default()).0;
        let table = radau(table::HexapodStanding::default()).0;
        println!("pair {pair}: Radau5, standing hexapod, 1 s: tangents as code {code:.1} ms, as a table {table:.1} ms");
        ratios.push(table / code);
    }
    ratios.sort_by(f64::total_cmp);
    println!(
        "table / code over {} pairs: {:.3} to {:.3}, median {:.3}",
        ratios.len(),
        ratios[0],
        ratios[ratios.len() - 1],
        ratios[ratios.len() / 2]
    );
}
RS
}

# (arm24-ensemble) no batch call of its own but an ensemble of four members, whose lanes
# read their models' parameters (`forward_dynamics_lanes`), as a program that runs ensembles
# and nothing else
ensemble_run() {
    echo 'pub fn batch(_: &Model) -> Option<f64> { None }'
    cat <<'RS'
pub fn run() {
    let options = mbs::Options {
        output: mbs::Output::Last,
        ..mbs::Options::adaptive(0.05, 1e-6)
    };
    let members = (0..4).map(|_| (Model::default(), mbs::Member::default()));
    let report = mbs::simulate_ensemble_each(mbs::Scheme::Dopri5, &options, members)
        .expect("an ensemble of the arm");
    println!("ensemble of {} runs", report.runs.len());
}
RS
}

cat > "$dir/src/main.rs" <<'RS'
#[allow(unused_macros, dead_code)]
mod model;
use mbs::Model;
fn main() {
    let m = model::Model::default();
    let n = model::Model::NQ;
    let (q, z) = (vec![0.1; n], vec![0.0; n]);
    let (mut qdd, mut p) = (vec![0.0; n], vec![0.0; n]);
    m.forward_dynamics(0.0, &q, &z, &vec![0.0; model::Model::NU], &mut qdd, &mut p);
    let batch = model::batch(&m).map_or(String::new(), |a| format!(" ({a:.6} in a batch)"));
    println!("{} dof, qdd[0] = {:.6}{batch}", n, qdd[0]);
    model::run();
}
RS

cd "$dir"
export CARGO_TARGET_DIR="$dir/target"
# for every build, the untimed ones too: a change of it rebuilds the path dependencies
export CARGO_INCREMENTAL=0
# the processor: build times, like run times, depend on it
if [ -r /proc/cpuinfo ]; then
    field() { grep -m1 "^$1[[:space:]]*:" /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//'; }
    echo "processor: $(field 'model name') (family $(field 'cpu family'), model $(field model))"
fi
cases=("${@:-arm24 chain32 hexapod hexapod-table hexapod-radau hexapod-table-radau chain200 arm24-dev arm24-batch arm24-ensemble}")
for case in ${cases[@]}; do
    profile=release
    case "$case" in
        arm24) { arm 24; no_run; } > src/model.rs ;;
        chain32) { chain 32; no_run; } > src/model.rs ;;
        chain200) { chain 200; no_run; } > src/model.rs ;;
        hexapod) { hexapod; no_run; } > src/model.rs ;;
        hexapod-radau) { hexapod; radau_run; } > src/model.rs ;;
        hexapod-code) { hexapod code; no_run; } > src/model.rs ;;
        hexapod-table) { hexapod table; no_run; } > src/model.rs ;;
        hexapod-table-radau) { hexapod table; radau_run; } > src/model.rs ;;
        tangent-forms) tangent_forms > src/model.rs ;;
        arm24-dev) { arm 24; no_run; } > src/model.rs; profile=dev ;;
        arm24-batch) { arm 24 batch; no_run; } > src/model.rs ;;
        arm24-ensemble) { arm 24 batch; ensemble_run; } > src/model.rs ;;
        *) echo "unknown case $case" >&2; exit 2 ;;
    esac
    flag=$([ "$profile" = release ] && echo --release || true)
    # dependencies (and a first build of the model) untimed
    cargo build -q $flag 2>/dev/null || cargo build $flag
    cargo clean -q -p one_model $flag
    /usr/bin/time -f "%e %M" -o "$dir/time" cargo build -q $flag
    read -r secs kib < "$dir/time"
    printf '%-10s %-7s build of the model crate: %6.1f s, peak %5.2f GB; ' "$case" "$profile" "$secs" "$(echo "$kib / 1048576" | bc -l)"
    cargo run -q $flag 2>/dev/null
done
