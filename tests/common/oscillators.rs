//! Three masses on springs along x, y and z, uncoupled, with exact tangents and their
//! stiffnesses `sensitive`: twin springs (a repeated pole), soft springs beside a stiff one.

mbs::multibody! {
    /// Three masses on springs along x, y, z; by default the springs along x and y equally
    /// stiff, so that their poles are one repeated pole, which moving kx alone splits.
    pub model Oscillators {
        param kx = 100.0 sensitive; param ky = 100.0 sensitive; param kz = 300.0 sensitive;
        param m = 1.0;
        option tangents;
        dof x = 0.0; dof y = 0.0; dof z = 0.0;
        body a { mass = m; inertia = (0.01, 0.01, 0.01); }
        body b { mass = m; inertia = (0.01, 0.01, 0.01); }
        body c { mass = m; inertia = (0.01, 0.01, 0.01); }
        TOG[a] = Tdisp(x, 0, 0);
        TOG[b] = Tdisp(0, y, 0);
        TOG[c] = Tdisp(0, 0, z);
        generalized_force(x, -kx * x);
        generalized_force(y, -ky * y);
        generalized_force(z, -kz * z);
    }
}
