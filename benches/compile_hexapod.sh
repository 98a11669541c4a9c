#!/usr/bin/env bash
# Compile time of the hexapod model with exact tangents, in a scratch crate that depends on
# this checkout: release, then a debug build with Cargo's default debuginfo.
#
#   benches/compile_hexapod.sh
#
# Dependencies are built first and not timed; each timed build compiles the model crate from
# scratch (its artifacts cleaned, no incremental cache).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/src"
cat > "$dir/Cargo.toml" <<TOML
[package]
name = "hexapod_tangents"
version = "0.0.0"
edition = "2024"
[dependencies]
mbs = { path = "$root" }
[workspace]
TOML
# the hexapod of models/src with `option tangents;` added before its closing braces
sed 's/^    }$/        option tangents;\n    }/' "$root/models/src/hexapod.rs" > "$dir/src/model.rs"
grep -q "option tangents" "$dir/src/model.rs"
cat > "$dir/src/main.rs" <<'RS'
mod model;
use mbs::Model;
fn main() {
    let m = model::Hexapod::default();
    let n = model::Hexapod::NQ;
    let (q, z) = (vec![0.1; n], vec![0.0; n]);
    let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
    m.tangents(0.0, &q, &z, &z, &[], &mut k, &mut c).unwrap();
    println!("K[0] = {}", k[0]);
}
RS
cd "$dir"
export CARGO_TARGET_DIR="$dir/target"
for profile in release dev; do
    flag=$([ "$profile" = release ] && echo --release || true)
    cargo build -q $flag 2>/dev/null || cargo build $flag
    cargo clean -q -p hexapod_tangents $flag
    start=$(date +%s.%N)
    CARGO_INCREMENTAL=0 cargo build -q $flag
    end=$(date +%s.%N)
    printf 'hexapod with tangents, %-7s build of the model crate: %.1f s\n' "$profile" "$(echo "$end - $start" | bc)"
    cargo run -q $flag
done
