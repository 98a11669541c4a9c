// Constants that fold to NaN or an infinity are reported on their tokens.
mbs::multibody! {
    model Folds {
        param l = asin(2.0);
        dof q[0] = 0.1;
        body bar { mass = 1.0 + ln(0.0); inertia = (0.01, 0.0, 0.01); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -sqrt(-1.0), 0) * Tdisp(0.0 / 0.0, l * pow(-8.0, 0.5), 0);
        generalized_force(q[0], -exp(1000.0) * q[0] + 1e400);
    }
}

fn main() {}
