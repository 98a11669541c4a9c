// Two swapped letters are one edit: `bsae` is close to `base`.
mbs::multibody! {
    model Arm {
        dof a = 0.1;
        body base { mass = 2.0; inertia = (0.02, 0.0, 0.02); }
        body arm { mass = 1.0; inertia = (0.01, 0.0, 0.01); }
        TOG[base] = Trotz(a) * Tdisp(0, -0.15, 0);
        TOG[arm] = TOG[bsae] * Tdisp(0, -0.3, 0);
    }
}

fn main() {}
