"""Reference solution of the fastlink mechanism (MODELS.md), computed outside mbs.

Independent of mbs's generator: every body has its own absolute coordinates
(x_i, y_i, phi_i) of its centre of mass (15 coordinates for 5 bodies); the joints are written
by hand as 14 scalar constraints; SymPy derives the mass matrix (constant), the generalized
forces from the potential (gravity, spring) and the motor torque, the constraint Jacobian B
and gamma = -d(B qd)/dq qd. The index-1 system

    [M  B^T] [qdd]   [F    ]
    [B  0  ] [-lam] = [gamma]

is integrated by SciPy's DOP853 at rtol = atol = 1e-13; checks: Radau at rtol = atol = 1e-12
(its limit) and DOP853 at 1e-11, their largest mixed error (floor 0.01) over the samples is
recorded, with the drift max |Phi|, |B qd| of the reference run. The states are mapped to mbs's coordinates
(absolute angles a, b, c, e of crank, coupler, rocker, rod; slider position s) and their rates.

Run:  python3 tests/reference/fastlink.py > tests/reference/fastlink.json
"""

import json
import sys
import time

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

# ---- parameters (MODELS.md, fastlink) ------------------------------------------------------
D = 0.06  # rocker pivot C = (D, 0); crank pivot O = (0, 0)
L1, L2, L3, L4 = 0.02, 0.05, 0.04, 0.06  # crank, coupler, rocker, rod
M1, M2, M3, M4, M5 = 0.004, 0.008, 0.006, 0.005, 0.015  # kg; slider M5
G = 9.81
K, L0, F0 = 2.0e4, 0.04, 0.0  # spring stiffness, rest length, preload
ANCHOR = (0.0, 0.07)  # spring from this ground point to the coupler's centre
TAU = 0.05  # N m, constant motor torque on the crank
A0 = 0.0  # crank angle at t = 0, crank at rest
T_END = 0.03
TIMES = [0.001 * k for k in range(1, 31)]


def bar_inertia(m, l):
    return m * l * l / 12.0


# ---- symbolic model in absolute coordinates --------------------------------------------------
nb = 5
q = sp.symbols("q0:15")
qd = sp.symbols("qd0:15")
X = [q[3 * i] for i in range(nb)]
Y = [q[3 * i + 1] for i in range(nb)]
P = [q[3 * i + 2] for i in range(nb)]


def at(i, u):
    """world point at distance u along body i's axis from its centre"""
    return sp.Matrix([X[i] + u * sp.cos(P[i]), Y[i] + u * sp.sin(P[i])])


masses = [M1, M2, M3, M4, M5]
inertias = [bar_inertia(M1, L1), bar_inertia(M2, L2), bar_inertia(M3, L3), bar_inertia(M4, L4), 0.0]
Mdiag = []
for i in range(nb):
    Mdiag += [masses[i], masses[i], inertias[i]]

O = sp.Matrix([0, 0])
C = sp.Matrix([D, 0])
crank_tip = at(0, L1 / 2)
phi = sp.Matrix.vstack(
    at(0, -L1 / 2) - O,  # crank hinged at O
    at(1, -L2 / 2) - crank_tip,  # coupler hinged at the crank tip
    at(2, -L3 / 2) - C,  # rocker hinged at C
    at(1, L2 / 2) - at(2, L3 / 2),  # loop 1: coupler end = rocker tip
    at(3, -L4 / 2) - at(2, L3 / 2),  # rod hinged at the rocker tip
    at(3, L4 / 2) - sp.Matrix([X[4], Y[4]]),  # loop 2: rod end = slider
    sp.Matrix([Y[4], P[4]]),  # slider on the x axis, not turning
)
assert phi.shape == (14, 1)

# potential: gravity, spring from the ground anchor to the coupler's centre
V = sum(masses[i] * G * Y[i] for i in range(nb))
ell = sp.sqrt((X[1] - ANCHOR[0]) ** 2 + (Y[1] - ANCHOR[1]) ** 2)
V += F0 * (ell - L0) + K * (ell - L0) ** 2 / 2
F = -sp.Matrix([V]).jacobian(q).T
F[2] += TAU  # motor torque on the crank (phi_0)

B = phi.jacobian(q)
qdv = sp.Matrix(qd)
gamma = -(B * qdv).jacobian(q) * qdv

f_phi = sp.lambdify([q], phi, "numpy", cse=True)
f_B = sp.lambdify([q], B, "numpy", cse=True)
f_F = sp.lambdify([q], F, "numpy", cse=True)
f_gamma = sp.lambdify([q, qd], gamma, "numpy", cse=True)
Mmat = np.diag(Mdiag)
n, m = 15, 14


def accel(qv, qdv):
    Bv = np.array(f_B(qv), dtype=float)
    A = np.zeros((n + m, n + m))
    A[:n, :n] = Mmat
    A[:n, n:] = Bv.T
    A[n:, :n] = Bv
    rhs = np.concatenate([np.array(f_F(qv), dtype=float).ravel(), np.array(f_gamma(qv, qdv), dtype=float).ravel()])
    sol = np.linalg.solve(A, rhs)
    return sol[:n], -sol[n:]


def rhs(_t, y):
    qdd, _ = accel(y[:n], y[n:])
    return np.concatenate([y[n:], qdd])


# ---- the consistent start: crank at A0, loop closed on the branch of MODELS.md ---------------
def assemble(a):
    """absolute angles (b, c, e) and slider s for crank angle a (coupler above the x axis)."""
    ax, ay = L1 * np.cos(a), L1 * np.sin(a)
    ux, uy = D - ax, -ay
    dist = np.hypot(ux, uy)
    along = (dist**2 + L2**2 - L3**2) / (2 * dist)
    across = np.sqrt(L2**2 - along**2)
    ex, ey = ux / dist, uy / dist
    px, py = ax + along * ex - across * ey, ay + along * ey + across * ex
    b = np.arctan2(py - ay, px - ax)
    c = np.arctan2(py, px - D)
    e = -np.arcsin(py / L4)
    s = px + L4 * np.cos(e)
    return b, c, e, s


def absolute(a, b, c, e, s):
    """the 15 absolute coordinates from mbs's (a, b, c, e, s)"""
    ca = np.array([L1 / 2 * np.cos(a), L1 / 2 * np.sin(a), a])
    tip = np.array([L1 * np.cos(a), L1 * np.sin(a)])
    cb = np.array([tip[0] + L2 / 2 * np.cos(b), tip[1] + L2 / 2 * np.sin(b), b])
    cc = np.array([D + L3 / 2 * np.cos(c), L3 / 2 * np.sin(c), c])
    rt = np.array([D + L3 * np.cos(c), L3 * np.sin(c)])
    ce = np.array([rt[0] + L4 / 2 * np.cos(e), rt[1] + L4 / 2 * np.sin(e), e])
    cs = np.array([s, 0.0, 0.0])
    return np.concatenate([ca, cb, cc, ce, cs])


def to_mbs(y):
    qv, qdv = y[:n], y[n:]
    return [qv[2], qv[5], qv[8], qv[11], qv[12]], [qdv[2], qdv[5], qdv[8], qdv[11], qdv[12]]


b0, c0, e0, s0 = assemble(A0)
q0 = absolute(A0, b0, c0, e0, s0)
y0 = np.concatenate([q0, np.zeros(n)])
assert np.max(np.abs(np.array(f_phi(q0), dtype=float))) < 1e-15


def run(method, tol):
    t0 = time.time()
    sol = solve_ivp(rhs, (0.0, T_END), y0, method=method, rtol=tol, atol=tol, t_eval=TIMES, dense_output=False)
    assert sol.success, sol.message
    return sol, time.time() - t0


sol, secs = run("DOP853", 1e-13)
chk, secs_chk = run("Radau", 1e-12)
loose, _ = run("DOP853", 1e-11)


def drift(sol):
    worst = 0.0
    for k in range(sol.y.shape[1]):
        qv, qdv = sol.y[:n, k], sol.y[n:, k]
        worst = max(worst, np.max(np.abs(np.array(f_phi(qv), dtype=float))))
        worst = max(worst, np.max(np.abs(np.array(f_B(qv), dtype=float) @ qdv)))
    return worst


def mixed(a, r, floor=0.01):
    return max(abs(x - y) / (floor + abs(y)) for x, y in zip(a, r))


states = []
agreement = []
loose_err = []
peak_acc = 0.0
for k, t in enumerate(TIMES):
    qm, qdm = to_mbs(sol.y[:, k])
    qc, qdc = to_mbs(chk.y[:, k])
    states.append({"t": t, "q": qm, "qd": qdm})
    agreement.append(mixed(qc + qdc, qm + qdm))
    ql, qdl = to_mbs(loose.y[:, k])
    loose_err.append(mixed(ql + qdl, qm + qdm))

# peak acceleration of a body's centre over a fine grid (context only)
fine = solve_ivp(rhs, (0.0, T_END), y0, method="DOP853", rtol=1e-10, atol=1e-10, t_eval=np.linspace(0, T_END, 3001))
for k in range(fine.y.shape[1]):
    qdd, _ = accel(fine.y[:n, k], fine.y[n:, k])
    for i in range(nb):
        peak_acc = max(peak_acc, float(np.hypot(qdd[3 * i], qdd[3 * i + 1])))
stretch0 = float(np.hypot(q0[3] - ANCHOR[0], q0[4] - ANCHOR[1])) - L0

out = {
    "model": "fastlink",
    "definition": "MODELS.md fastlink (models/src/fastlink.rs)",
    "source": "SymPy %s: Lagrange's equations with multipliers in absolute coordinates (x, y, phi of each body's centre, "
    "15 coordinates, 14 joint constraints written by hand), index-1 form integrated by SciPy %s DOP853 at rtol = atol = 1e-13, "
    "checked by SciPy Radau at rtol = atol = 1e-12; mapped to mbs's (a, b, c, e, s)" % (sp.__version__, __import__("scipy").__version__),
    "script": "tests/reference/fastlink.py",
    "coordinates": "q = (a, b, c, e, s): absolute angles of crank, coupler, rocker, rod (from +x, counter-clockwise), slider x; qd their rates",
    "initial": {"q": list(to_mbs(y0)[0]), "qd": [0.0] * 5},
    "states": states,
    "check_radau_mixed_error": agreement,
    "check_radau_max_mixed_error": max(agreement),
    "check_dop853_rtol_1e-11_max_mixed_error": max(loose_err),
    "mixed_error_floor": 0.01,
    "spring_stretch_at_start_m": stretch0,
    "max_drift_phi_and_phidot": drift(sol),
    "peak_body_acceleration_m_s2": peak_acc,
    "timing_s": {"dop853": secs, "radau": secs_chk},
    "nfev": {"dop853": int(sol.nfev), "radau": int(chk.nfev)},
}
json.dump(out, sys.stdout, indent=1)
print()
