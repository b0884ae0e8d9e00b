"""The complex step of the quadratic velocity terms and of the derivative checks.

f(Q + i h Q_dot) gives the directional derivative (df/dQ) Q_dot = Im f / h to machine precision:
there is no subtraction, so no cancellation, and any tiny h works (W. Squire, G. Trapp, "Using
complex variables to estimate derivatives of real functions", SIAM Review 40 (1998) 110-112;
J. R. R. A. Martins, P. Sturdza, J. J. Alonso, ACM TOMS 29 (2003) 245-262).  Every module that
takes a complex step uses this one value; only operations analytic in the complex plane may
touch the stepped state.
"""

COMPLEX_STEP = 1e-20
