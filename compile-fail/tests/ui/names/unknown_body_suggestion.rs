mbs::multibody! {
    model Arm {
        dof shoulder = 0.1; dof elbow = 0.2;
        body upper_arm { mass = 2.0; inertia = (0.02, 0.0, 0.02); }
        body forearm { mass = 1.0; inertia = (0.01, 0.0, 0.01); }
        TOG[upper_arm] = Trotz(shoulder) * Tdisp(0, -0.15, 0);
        TOG[forearm] = TOG[uper_arm] * Tdisp(0, -0.15, 0) * Trotz(elbow) * Tdisp(0, -0.15, 0);
    }
}

fn main() {}
