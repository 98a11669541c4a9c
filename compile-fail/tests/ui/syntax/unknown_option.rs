mbs::multibody! {
    model Pendulum {
        dof q[0] = 0.5;
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        option tangent;
        option formulation = lagrange;
        option batch = 4;
        option jacobians = sparse;
        option jacobians;
        option tangents = sparse;
        option tangents = 2;
        option motion = true;
    }
}

fn main() {}
