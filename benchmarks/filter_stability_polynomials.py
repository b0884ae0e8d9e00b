"""How far an explicit method tailored to the stress filter can step: the largest step of an
s-stage explicit Runge-Kutta method of linear order p whose stability polynomial holds every
eigenvalue the filtered booms can have.

One command (from the repository root; a design calculation, no timing):

    python benchmarks/filter_stability_polynomials.py

The filter of the SIMULTECH 2020 paper (Eq. 53; ``StressFilter``: (h_f^2/6) K added to the mass,
(h_f/2) K to the damping) moves a mode of undamped angular frequency w to the roots of

    (1 + h_f^2 w^2 / 6) lambda^2 + (h_f w^2 / 2) lambda + w^2 = 0,

a curve from the imaginary axis (w -> 0) to the pair (3/h_f)(-1/2 +- i sqrt(5/12)) (w -> oo)
that every stiff mode ends on (docs/model.md, Time integration).  Modes whose stiffness is
partly unfiltered lie between that curve and the imaginary axis: in the paper scene's spectrum
(``benchmarks/results/sliding_integrators.md``) only low ones (the rope-payload mode at 23
rad/s, the compression-softened first bending modes at 3-5 rad/s); every mode above 60 rad/s
sits on the curve.  A step must also hold the eigenvalues at every smaller step the controller
may take, the curve scaled by 0..1.  The region a step h must hold is therefore h x {the curve
and its scaled copies, the area between the curve and the imaginary axis up to ``--free``
(default 60) rad/s, the Baumgarte roots on [-25, 0] 1/s}.

For each (p, s) the largest h is found by bisection; at each h the free coefficients of
R(z) = sum_{k<=p} z^k/k! + sum_{p<k<=s} alpha_k z^k minimise max |R| over the region's samples,
a linear programme (|R| <= t replaced by Re(e^{-i theta} R) <= t at 24 directions, which
overestimates |R| by at most 1/cos(pi/24) - 1 = 0.9 %); h is feasible where the optimum is
<= 1.  This bounds what any such method can gain: the nonlinear order conditions, an embedded
error estimator and internal stability only take away from it.  Dormand-Prince (RK45: 6 new
stages per step, p = 5) is in the first row for comparison.

A second table gives the explicit multistep alternative, 2 right-hand sides per step: the
Adams-Bashforth-Moulton predictor-corrector of order k in PECE mode (Hairer, Norsett, Wanner,
Solving ODEs I, Sect. III.1; AB_k predictor, AM_k corrector, k past values each), whose step h
holds the region (and, separately, the filter pair's ray alone) where every root of its
amplification matrix (:func:`adams_pece_modulus`) is at most 1 in modulus.

``--out FILE``: the markdown table (default
``benchmarks/results/filter_stability_polynomials.md``).
"""

from __future__ import annotations

import argparse
import os
from math import factorial

import sys

import numpy as np
from scipy.optimize import linprog

_HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.abspath(os.path.join(_HERE, "..")))
sys.path.insert(0, _HERE)

from _machine import write_markdown  # noqa: E402



def region(h_f: float = 0.01, w_free: float = 60.0) -> np.ndarray:
    """Sample points (1/s, upper half plane) of the eigenvalue region of the filtered booms,
    with partly unfiltered modes up to ``w_free`` rad/s."""
    c1, c2 = h_f / 2.0, h_f * h_f / 6.0
    w = np.concatenate([np.linspace(0.0, 400.0, 300), np.geomspace(400.0, 1e6, 100)])
    a, b, c = 1.0 + c2 * w * w, c1 * w * w, w * w
    curve = (-b + 1j * np.sqrt(4.0 * a * c - b * b + 0j)) / (2.0 * a)
    fan = np.concatenate([f * curve for f in np.linspace(0.05, 1.0, 20)])
    low = curve[np.abs(curve) <= w_free]
    between = np.array([x * z.real + 1j * z.imag for z in low for x in np.linspace(0.0, 1.0, 6)])
    return np.concatenate([curve, fan, between, 1j * np.linspace(0.0, w_free, 40),
                           -np.linspace(0.0, 25.0, 10)])


def max_modulus(z: np.ndarray, s: int, p: int, directions: int = 24) -> float:
    """min over alpha of max |R(z)| (the linear programme of the module docstring)."""
    taylor = sum(z ** k / factorial(k) for k in range(p + 1))
    if s == p:
        return float(np.max(np.abs(taylor)))
    Z = np.stack([z ** k for k in range(p + 1, s + 1)], axis=1)
    th = np.linspace(0.0, 2.0 * np.pi, directions, endpoint=False)
    A = np.vstack([np.hstack([(np.exp(-1j * t) * Z).real, -np.ones((len(z), 1))]) for t in th])
    b = np.concatenate([-(np.exp(-1j * t) * taylor).real for t in th])
    cost = np.zeros(s - p + 1)
    cost[-1] = 1.0
    r = linprog(cost, A_ub=A, b_ub=b, bounds=[(None, None)] * (s - p) + [(0.0, None)],
                method="highs")
    return float(r.fun) if r.success else np.inf


def dormand_prince_modulus(z: np.ndarray) -> float:
    """max |R(z)| of Dormand-Prince 5(4) (RK45): its degree-6 stability polynomial."""
    R = sum(z ** k / factorial(k) for k in range(6)) + z ** 6 / 600.0
    return float(np.max(np.abs(R)))


def adams_coefficients(k: int) -> tuple[np.ndarray, np.ndarray]:
    """(b, c) of Adams-Bashforth and Adams-Moulton with k past values: y_{n+1} = y_n + h sum_j
    b_j f_{n-j} (j = 0..k-1) and y_{n+1} = y_n + h sum_j c_j f_{n+1-j} (j = 0..k-1), the
    integrals over [t_n, t_{n+1}] of the Lagrange polynomials through the nodes (order k)."""
    P = np.polynomial.polynomial

    def weights(nodes):
        out = []
        for m in nodes:
            poly = np.array([1.0])
            for x in nodes:
                if x != m:
                    poly = P.polymul(poly, np.array([-x, 1.0]) / (m - x))
            prim = P.polyint(poly)
            out.append(P.polyval(1.0, prim) - P.polyval(0.0, prim))
        return np.array(out)

    return weights([-j for j in range(k)]), weights([1 - j for j in range(k)])


def adams_pece_modulus(z: np.ndarray, k: int) -> float:
    """Largest root modulus over z of Adams-Bashforth-Moulton PECE of order k on y' = lambda
    y, z = h lambda: the state (y_n, h f_n, .., h f_{n-k+1}) maps to (y_c, z y_c, h f_n, ..,
    h f_{n-k+2}) with y_p = y_n + sum_j b_j h f_{n-j} and y_c = y_n + c_0 z y_p +
    sum_{j>=1} c_j h f_{n+1-j}."""
    b, c = adams_coefficients(k)
    z = np.asarray(z, dtype=complex).ravel()
    A = np.zeros((z.size, k + 1, k + 1), dtype=complex)
    for col in range(k + 1):
        v = np.zeros(k + 1)
        v[col] = 1.0
        y, F = v[0], v[1:]
        yp = y + b @ F
        yc = y + c[0] * z * yp + c[1:] @ F[:k - 1]
        A[:, 0, col] = yc
        A[:, 1, col] = z * yc
        A[:, 2:, col] = F[:k - 1]
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def largest_step(modulus, pts, h_hi: float = 0.2, bisections: int = 24) -> float:
    lo, hi = 0.0, h_hi
    for _ in range(bisections):
        mid = 0.5 * (lo + hi)
        if modulus(mid * pts) <= 1.0 + 1e-9:
            lo = mid
        else:
            hi = mid
    return lo


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--filter-h", type=float, default=0.01)
    ap.add_argument("--free", type=float, default=60.0)
    ap.add_argument("--out", default=os.path.join(_HERE, "results",
                                                  "filter_stability_polynomials.md"))
    a = ap.parse_args(argv)
    pts = region(a.filter_h, a.free)
    h_dp = largest_step(dormand_prince_modulus, pts)
    rows = [("Dormand–Prince (RK45)", 5, 6, h_dp)]
    print(f"RK45 h_max {h_dp * 1e3:.2f} ms", flush=True)
    for p in (4, 5):
        for s in range(p + 2, 13):
            h = largest_step(lambda z, s=s, p=p: max_modulus(z, s, p), pts)
            rows.append((f"optimal polynomial, order {p}", p, s, h))
            print(f"p {p} s {s:2d} h_max {h * 1e3:6.2f} ms", flush=True)
    pair = (3.0 / a.filter_h) * (-0.5 + 1j * np.sqrt(5.0 / 12.0))
    ray = pair * np.linspace(0.0, 1.0, 201)[1:]
    adams = []
    for k in (3, 4, 5):
        h = largest_step(lambda z, k=k: adams_pece_modulus(z, k), pts)
        h_ray = largest_step(lambda z, k=k: adams_pece_modulus(z, k), ray)
        adams.append((k, h, h_ray))
        print(f"ABM PECE order {k} h_max {h * 1e3:6.2f} ms, on the ray {h_ray * 1e3:6.2f} ms",
              flush=True)
    lines = [
        "# Explicit steps under the stress filter: the stability bound",
        "",
        f"Filter window h_f = {a.filter_h:g} s (the paper scene), partly unfiltered modes up to "
        f"{a.free:g} rad/s.  Largest step h at which a "
        "stability polynomial of degree s (stages) and linear order p holds the filtered "
        "booms' eigenvalue region; written by `benchmarks/filter_stability_polynomials.py` "
        "(its docstring: the region and the linear programme).  Right-hand sides per "
        "simulated second = s / h (RK45: 6 per step, first-same-as-last).",
        "",
        "| stability polynomial | p | stages s | h_max (ms) | ms per stage | right-hand sides "
        "per simulated s | vs RK45 |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, p, s, h in rows:
        lines.append(f"| {name} | {p} | {s} | {h * 1e3:.1f} | {h * 1e3 / s:.2f} | "
                     f"{s / h:.0f} | {(6 / h_dp) / (s / h):.2f} |")
    lines += [
        "",
        "Explicit multistep: Adams-Bashforth-Moulton PECE, 2 right-hand sides per step, over "
        "the same region and over the filter pair's ray alone (the stiff modes; the region "
        "also holds the undamped low modes on the imaginary axis, where the roots of orders 3 "
        "and 4 exceed 1 by O(|z|^4) and O(|z|^6)).  Right-hand sides per simulated second at "
        "the ray's bound, an upper bound on what the method gains.",
        "",
        "| order | h_max, region (ms) | h_max, filter pair's ray (ms) | right-hand sides per "
        "simulated s (ray) | vs RK45 |",
        "|---|---|---|---|---|",
    ]
    for k, h, h_ray in adams:
        lines.append(f"| {k} | {h * 1e3:.2f} | {h_ray * 1e3:.2f} | {2 / h_ray:.0f} | "
                     f"{(6 / h_dp) / (2 / h_ray):.2f} |")
    write_markdown(a.out, lines)


if __name__ == "__main__":
    main()
