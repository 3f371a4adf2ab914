"""How likely is the paper's S2 random row (3/10 found, mean 150.4, a failure counted as 200) from one fixed cell?

    python benchmarks/s2_paper_random_odds.py

With independent episodes of per-episode hazard probability p, a run's first hit is geometric(p), censored at
200. A mean <= 150.4 with 3 of 10 found needs the 3 hits to sum to <= 104 (1504 - 1400); with <= 2 found the mean
is >= 160.2. So P = C(10,3) (1-p)^(7*200) P(Binomial(104, p) >= 3) exactly; printed: its maximum over p, and for
comparison the same for a two-class mixture (a share f of runs with probability p per episode, the rest with 0).
"""

from __future__ import annotations

from math import comb

import numpy as np
from scipy import stats


def fixed(p):
    return comb(10, 3) * (1 - p) ** 1400 * stats.binom.sf(2, 104, p)


def mixture(f, p):
    q = 1 - (1 - p) ** 200
    return comb(10, 3) * (1 - f * q) ** 7 * f ** 3 * stats.binom.sf(2, 104, p)


def main() -> None:
    ps = np.linspace(1e-5, 0.03, 30000)
    v = fixed(ps)
    i = int(v.argmax())
    print(f"one fixed cell: max over p of P(3/10 found, mean <= 150.4) = {v[i]:.5f} at p = {ps[i]:.5f}")
    for p in (0.0029, 0.005, 0.01):
        print(f"  p = {p}: {fixed(p):.5f}")
    for f, p in ((0.3, 0.03), (0.35, 0.025), (0.4, 0.02)):
        print(f"mixture: share {f} of runs at p = {p}, the rest impossible: {mixture(f, p):.4f}")


if __name__ == "__main__":
    main()
