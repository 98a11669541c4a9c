// A declaration that takes a reserved name is reported once, at the declaration; its uses
// are not reported again as unknown names.
mbs::multibody! {
    model Pendulum {
        param u = 1.0;
        dof qd = 0.5;
        body TOG { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -u, 0);
        TOG[TOG] = TOG[bar] * Trotz(q[qd]) * Tdisp(0, -u, 0);
        generalized_force(q[0], -u * qd);
        spring(TOG, bar, k = u, l0 = 0.1);
    }
}

fn main() {}
