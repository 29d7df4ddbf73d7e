"""Shared test fixtures: the paper's shapes, poses, and oracles written here in
NumPy/SciPy, sharing no code with the solver."""
import math

import numpy as np
import scipy.linalg
import scipy.optimize

import idcol

S3 = 1.0 / math.sqrt(3.0)
OCTA = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1],
                 [-1, -1, -1], [-1, 1, 1], [1, -1, 1], [1, 1, -1]], float) * S3
OCTA_B = np.array([1, 1, 1, 1, 5 / 3, 5 / 3, 5 / 3, 5 / 3]) * S3


def paper_shapes():
    """The paper's Table 1 shapes by name (beta = 20, n = 8)."""
    return {
        "Poly": idcol.SmoothPolytope(OCTA, OCTA_B, beta=20.0),
        "TC": idcol.SmoothTruncatedCone(Rb=1.0, Rt=1.5, a=1.5, b=1.5, beta=20.0),
        "SE": idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=8),
        "SEC": idcol.SuperellipticCylinder(R=1.0, h=2.0, n=8),
    }


def hat(xi):
    """4x4 matrix of a twist xi = (w, v)."""
    w, v = xi[:3], xi[3:]
    T = np.zeros((4, 4))
    T[:3, :3] = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    T[:3, 3] = v
    return T


def perturb(R, p, xi):
    """(R, p) exp(xi^), the exponential by scipy.linalg.expm (not idcol's)."""
    G = np.eye(4)
    G[:3, :3], G[:3, 3] = R, p
    G = G @ scipy.linalg.expm(hat(xi))
    return G[:3, :3].copy(), G[:3, 3].copy()


def random_rotation(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def random_poses(rng, n, rmin, rmax):
    R = np.stack([random_rotation(rng) for _ in range(n)])
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    r = np.exp(rng.uniform(math.log(rmin), math.log(rmax), size=n))
    return R, d * r[:, None]


def paper_poses(n, rmin, rmax, dt=1e-4):
    """The paper's sweep (README, "Generators"), pose k at t = k dt."""
    t = np.arange(n) * dt
    tp = 2 * math.pi
    u = 0.5 * (1 + np.sin(tp * math.sqrt(2) * t))
    rad = np.cbrt(rmin ** 3 + (rmax ** 3 - rmin ** 3) * u)
    th = 0.5 * math.pi * np.sin(tp * math.sqrt(3) * t)
    ph = tp * math.sqrt(5) * t
    p = rad[:, None] * np.stack([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), np.sin(th)], axis=1)
    q = np.stack([np.sin(tp * math.sqrt(7) * t), np.cos(tp * math.sqrt(11) * t),
                  np.sin(tp * math.sqrt(13) * t), np.cos(tp * math.sqrt(17) * t)], axis=1)
    q /= np.linalg.norm(q, axis=1)[:, None]
    w, x, y, z = q.T
    R = np.empty((n, 3, 3))
    R[:, 0] = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=1)
    R[:, 1] = np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=1)
    R[:, 2] = np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1)
    return R, p


def radial_range(a, b):
    (i1, o1), (i2, o2) = a.radii, b.radii
    return 0.1 * min(i1, i2), 2.0 * max(o1, o2)


def superellipsoid_phi(abc, n, y):
    """phi of a superellipsoid, written out."""
    return np.sum(np.abs(np.asarray(y) / np.asarray(abc)) ** (2 * n)) ** (1 / (2 * n)) - 1


def ellipsoid_alpha(axes1, axes2, R, p):
    """alpha* of two ellipsoids scaled about their centres, by the
    Perram-Wertheim contact function: alpha*^2 = max over l in [0, 1] of
    l (1 - l) p^T [(1 - l) A1^-1 + l A2^-1]^-1 p, A_i^-1 = R_i diag(axes^2) R_i^T."""
    A1 = np.diag(np.asarray(axes1, float) ** 2)
    A2 = R @ np.diag(np.asarray(axes2, float) ** 2) @ R.T

    def neg_f(lam):
        return -lam * (1 - lam) * p @ np.linalg.solve((1 - lam) * A1 + lam * A2, p)

    res = scipy.optimize.minimize_scalar(neg_f, bounds=(0, 1), method="bounded",
                                         options={"xatol": 1e-14})
    return math.sqrt(-res.fun)
