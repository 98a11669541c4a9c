use mbs_symbolic::expr::OpCount;
use mbs_symbolic::{SymbolicModel, systems_from_str};
use std::time::Instant;

fn chain(n: usize) -> String {
    let mut s = String::from("model Chain { param l = 0.5; param m = 1.0; param g = 9.81;\n");
    for i in 0..n {
        s += &format!(
            "dof q[{i}] = 0.3; body b{i} {{ mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }}\n"
        );
    }
    s += "TOG[b0] = Trotz(q[0]) * Tdisp(0, -l/2, 0);\n";
    for i in 1..n {
        s += &format!(
            "TOG[b{i}] = TOG[b{}] * Tdisp(0, -l/2, 0) * Trotz(q[{i}]) * Tdisp(0, -l/2, 0);\n",
            i - 1
        );
    }
    s += "gravity(0, -g, 0); }";
    s
}

fn main() {
    for n in [2, 4, 8, 12, 24, 48] {
        let t0 = Instant::now();
        let sys = systems_from_str(&chain(n)).unwrap().remove(0);
        let t1 = Instant::now();
        let model = SymbolicModel::build(sys);
        let t2 = Instant::now();
        let e = &model.scenes[0];
        let a = &model.sys.arena;
        let lower = |m: &Vec<Vec<_>>| {
            let mut v = vec![];
            for (r, row) in m.iter().enumerate() {
                v.extend_from_slice(&row[..=r]);
            }
            v
        };
        let vm = OpCount::of(a, &lower(&e.vp.m));
        let vh = OpCount::of(a, &e.vp.h);
        let rm = OpCount::of(a, &lower(&e.rec.m));
        let rh = OpCount::of(a, &e.rec.h);
        let rmh = OpCount::of(a, &e.rec.roots());
        let vmh = OpCount::of(a, &e.vp.roots());
        let tr = OpCount::of(a, &e.tau_rec);
        println!(
            "chain{n}: parse {:?} build {:?} arena {} | VP M {} h {} M+h {} | REC M {} ({:.1} n²) h {} ({:.1}/dof) M+h {} | tau_rec {} | chose {:?}",
            t1 - t0,
            t2 - t1,
            a.len(),
            vm.flops(),
            vh.flops(),
            vmh.flops(),
            rm.flops(),
            rm.flops() as f64 / (n * n) as f64,
            rh.flops(),
            rh.flops() as f64 / n as f64,
            rmh.flops(),
            tr.flops(),
            e.formulation
        );
    }
}
