mbs::multibody! {
    model Mount {
        dof x = 0.0;
        body engine { mass = 10.0; inertia = (1.0, 1.0, 1.0); }
        point lug on engine at (0.2, 0, 0);
        TOG[engine] = Tdisp(x, 0, 0);
        bushing(engine, engine, k = 1e4);
        bushing(ground, engine);
        bushing(ground, engine, k = (1e4, 1e4));
        bushing(ground, lug, k = 1e4);
        bushing(ground, engine, k = (1e4, -1e4, 1e4), cr = -2.0);
        bushing(engine, k = 1e4);
    }
}

fn main() {}
