"""Small pieces every pairwise kernel shares: the separation of two particles and adding
an equal and opposite force to both (numba, inlined into the kernels that call them), and
joining per-element record arrays end to end."""
from __future__ import annotations

from dataclasses import fields
from typing import TypeVar

import numba
import numpy as np

Record = TypeVar("Record")


@numba.njit(cache=True, inline="always")
def separation(position, i, j):
    """``x_j − x_i`` (three floats, metres) and its length, for ``position`` (N, 3)."""
    d0 = position[j, 0] - position[i, 0]
    d1 = position[j, 1] - position[i, 1]
    d2 = position[j, 2] - position[i, 2]
    return d0, d1, d2, np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@numba.njit(cache=True, inline="always")
def add_pair_force(out, i, j, f0, f1, f2):
    """``out_i += f`` and ``out_j −= f`` (Newton's third law), ``out`` (N, 3) newtons."""
    out[i, 0] += f0
    out[i, 1] += f1
    out[i, 2] += f2
    out[j, 0] -= f0
    out[j, 1] -= f1
    out[j, 2] -= f2


def concatenate_records(cls: type[Record], parts: list[Record]) -> Record:
    """Join dataclass records of per-element arrays end to end, field by field.

    Every field annotated ``np.ndarray`` is concatenated along its first axis; other fields
    (a version counter …) take their defaults.
    """
    arrays = [f.name for f in fields(cls) if f.type in ("np.ndarray", np.ndarray)]
    return cls(**{name: np.concatenate([getattr(p, name) for p in parts]) for name in arrays})
