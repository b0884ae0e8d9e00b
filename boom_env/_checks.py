"""Argument checks of the environments' constructors and reset options: TypeError for a value
of the wrong type, ValueError for a value out of its range, each message naming the argument."""

from __future__ import annotations

import math

import numpy as np


def number(name, v):
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer,
                                                             np.floating)):
        raise TypeError(f"{name} = {v!r}: must be a real number")
    v = float(v)
    if not math.isfinite(v):
        raise ValueError(f"{name} = {v!r}: must be finite")
    return v


def positive(name, v, hi=math.inf):
    v = number(name, v)
    if not 0 < v <= hi:
        raise ValueError(f"{name} = {v!r}: allowed (0, {hi:g}]")
    return v


def nonneg(name, v):
    v = number(name, v)
    if v < 0:
        raise ValueError(f"{name} = {v!r}: allowed [0, inf)")
    return v


def in_range(name, v, lo, hi):
    v = number(name, v)
    if not lo - 1e-9 <= v <= hi + 1e-9:
        raise ValueError(f"{name} = {v!r}: allowed [{lo:g}, {hi:g}]")
    return min(max(v, lo), hi)


def range_pair(name, v, lo, hi):
    if v is None:
        return None
    if isinstance(v, (str, bytes)) or not hasattr(v, "__len__") or len(v) != 2:
        raise TypeError(f"{name} = {v!r}: must be a pair (lo, hi) or None")
    a, b = (in_range(name, x, lo, hi) for x in v)
    if a > b:
        raise ValueError(f"{name} = {v!r}: lo > hi")
    return (a, b)


def flag(name, v):
    if not isinstance(v, (bool, np.bool_)):
        raise TypeError(f"{name} = {v!r}: must be True or False")
    return bool(v)


def integer(name, v, allowed):
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
        raise TypeError(f"{name} = {v!r}: must be an integer, allowed {allowed}")
    if int(v) not in allowed:
        raise ValueError(f"{name} = {v!r}: allowed {allowed}")
    return int(v)
