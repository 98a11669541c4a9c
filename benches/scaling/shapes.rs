// The two shapes of the scaling benchmark as `macro_rules!` around `multibody!`, so that each
// size is one line (`benches/compile_time.sh` writes its models from this file too):
// - `chain!(Name, n)`: n uniform bars (l = 0.5 m, 1 kg) hinged end to end about +z, relative
//   angles, q(0) = 0.3 rad, gravity along −y (as `chain8` and `chain24` of `mbs-models`);
// - `arm!(Name, n, pairs, last, before_last)`: n revolute joints, axes z, y, z, y… each in the
//   previous link's frame, 0.3 m boxes of 1 kg along x, q(0) = 0.2 rad, gravity along −z (as
//   `arm3d_6`); `pairs` = n/2 − 1, `last` = n − 1, `before_last` = n − 2 (the language's
//   loop ranges and indices outside loops are written numbers).
// Options of the language follow: `chain!(Name, 16, batch)`, `chain!(Name, 32, jacobians = assembled)`.

macro_rules! chain {
    ($name:ident, $n:tt $(, $option:ident $(= $value:ident)?)*) => {
        mbs::multibody! {
            /// Planar chain of uniform bars.
            pub model $name {
                param l = 0.5; param m = 1.0; param g = 9.81;
                for i in 0..$n {
                    dof q[i] = 0.3;
                    body bar[i] { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
                }
                TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
                for i in 1..$n {
                    TOG[bar[i]] = TOG[bar[i-1]] * Tdisp(0, -l/2, 0) * Trotz(q[i]) * Tdisp(0, -l/2, 0);
                }
                gravity(0, -g, 0);
                $(option $option $(= $value)?;)*
            }
        }
    };
}

macro_rules! arm {
    ($name:ident, $n:tt, $pairs:tt, $last:tt, $before:tt $(, $option:ident $(= $value:ident)?)*) => {
        mbs::multibody! {
            /// Spatial arm of revolute joints, axes z, y alternating.
            pub model $name {
                param g = 9.81; param len = 0.3; param w = 0.05; param m = 1.0;
                let ixx = m * (w * w + w * w) / 12;
                let iyy = m * (len * len + w * w) / 12;
                for i in 0..$n {
                    dof q[i] = 0.2;
                    body link[i] { mass = m; inertia = (ixx, iyy, iyy); }
                }
                TOG[link[0]] = Trotz(q[0]) * Tdisp(len / 2, 0, 0);
                for k in 0..$pairs {
                    TOG[link[2*k+1]] = TOG[link[2*k]] * Tdisp(len / 2, 0, 0) * Troty(q[2*k+1]) * Tdisp(len / 2, 0, 0);
                    TOG[link[2*k+2]] = TOG[link[2*k+1]] * Tdisp(len / 2, 0, 0) * Trotz(q[2*k+2]) * Tdisp(len / 2, 0, 0);
                }
                TOG[link[$last]] = TOG[link[$before]] * Tdisp(len / 2, 0, 0) * Troty(q[$last]) * Tdisp(len / 2, 0, 0);
                gravity(0, 0, -g);
                $(option $option $(= $value)?;)*
            }
        }
    };
}
