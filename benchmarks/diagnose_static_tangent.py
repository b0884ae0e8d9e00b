"""Diagnostic (open problem): the telescopic static residual at n_nodes = 9 is not consistent
with its forward-difference tangent along the Newton direction.

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/diagnose_static_tangent.py 9

prints |r(z + e d) - (r + e (K d + C^T dl))| for e = 1e-6 ... 1: for a differentiable residual it
falls as e^2; measured at n_nodes = 9 (case 9.1) it grows *linearly* (0.18 N at e = 1e-6, 1.8e5 N
at e = 1), although the tangent's columns agree for h = 1e-6 and 1e-8 to 2e-6 -- a kink or a
discrete switch in the residual along combined moves.  At n_nodes = 3 Newton converges in 4
iterations, and there the same check gives |cen - K d| = 0.2 % of |K d|.  At n_nodes = 9 the central
difference along d (e = 1e-5) differs from K d by 200 % while forward and backward differences
agree to 1 %: the mismatch sits in the moves of booms 2 and 3 (whose junction s_3 is a
coordinate), not boom 1 (junction fixed at L_h).  Kept to reproduce the problem; the statics
use central differences because of it (sim_core.model.statics.force_tangent, CHANGELOG.md).
"""
import sys

import numpy as np

from sim_core.physics.constraints import constraint_terms
from sim_core.systems.telescopic.params import TelescopicParams
from sim_core.systems.telescopic.build import build_telescopic

p = TelescopicParams(n_nodes=int(sys.argv[1]), friction=False, E=2.1e12, payload=1000.0)
ts = build_telescopic(p); m = ts.model
for r in m.point_effects:
    if r.name=="retraction_rope": r.L0=np.inf
z,_ = m.reduced_state(0.0, ts.Q0, 0*ts.Q0); t=0.0
def parts(zz):
    Q, Qd = m.full_state(t, zz, np.zeros_like(zz))
    _, F = m.mass_force(t, Q, np.zeros_like(Q), mass=False)
    phi, J, _, _ = constraint_terms(m.nonlinear, t, Q, np.zeros_like(Q))
    return m.P.T @ F, phi, J @ m.P
n=len(z); Fr, phi, C = parts(z)
lam = np.linalg.lstsq(C.T, -Fr, rcond=None)[0]
def res(zz):
    F_, p_, C_ = parts(zz); return F_ + C_.T@lam
r1 = res(z)
def tangent(h):
    K = np.empty((n,n))
    for j in range(n):
        zj=z.copy(); zj[j]+=h; K[:,j]=(res(zj)-r1)/h
    return K
K1 = tangent(1e-6); K2 = K1
err = np.abs(K1-K2).max(axis=0)/ (np.abs(K1).max()+1e-30)
worst = np.argsort(-err)[:6]
print("max col rel diff h=1e-6 vs 1e-8", err.max(), "worst cols", worst, err[worst])
# which full coords are these columns
for j in worst: print(j, np.nonzero(np.abs(m.P[:, j])>1e-12)[0][:5])
mm=C.shape[0]
A=np.block([[K1,C.T],[C,np.zeros((mm,mm))]])
D=np.linalg.solve(A,-np.concatenate([r1,phi])); d=D[:n]; dl=D[n:]
for eps in (1e-6,1e-4,1e-2,1e-1,1.0):
    lin = r1 + eps*(K1@d + C.T@dl)
    F_,p_,C_ = parts(z+eps*d); act = F_ + C_.T@(lam+eps*dl)
    print(eps, "|r(z+ed)|", np.linalg.norm(act), "|lin|", np.linalg.norm(lin), "|act-lin|", np.linalg.norm(act-lin))
