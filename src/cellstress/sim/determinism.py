"""A determinism checker (in the spirit of gymnasium's ``check_step_determinism``).

The simulator promises that the same state and action give bit-identical results, whichever way an episode
is played: whole (``run``), step by step (``step``), resumed from a snapshot, or in a parallel batch.
``check_determinism`` plays the same sequences all those ways and compares the raw bits.
"""

from __future__ import annotations

import numpy as np

from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator


class DeterminismError(AssertionError):
    """Two ways of playing the same episode disagreed."""


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and np.array_equal(np.ascontiguousarray(a).view(np.uint64),
                                                 np.ascontiguousarray(b).view(np.uint64))


def check_determinism(sim: Simulator, sequences, repeats: int = 2) -> int:
    """Raise DeterminismError at the first disagreement; return the number of episodes checked."""
    seqs = [[sim.action_index(a) for a in seq] for seq in sequences]
    for n, seq in enumerate(seqs):
        ref = sim.run(seq).rows
        for _ in range(repeats - 1):
            if not _same_bits(sim.run(seq).rows, ref):
                raise DeterminismError(f"sequence {n}: two runs of the same episode differ")
        # step by step, snapshotting and restoring before every action
        state = sim.reset()
        rows = [sim.initial_metrics()[None, :]]
        for a in seq:
            state = sim.restore(sim.snapshot(state))
            state, r = sim.step(state, a)
            rows.append(r)
            if sim.is_unsafe(state):
                break
        stepped = np.concatenate(rows)
        if not _same_bits(stepped, ref):
            bad = int(np.flatnonzero(np.any(stepped[:len(ref)] != ref[:len(stepped)], axis=1))[0]) \
                if stepped.shape == ref.shape else min(len(stepped), len(ref))
            raise DeterminismError(f"sequence {n}: step-by-step play differs from run() at row {bad}")
    # the parallel batch agrees with single episodes at every action end
    width = max(len(s) for s in seqs)
    same_len = [s for s in seqs if len(s) == width]
    if same_len:
        batch = sim.run_batch(np.asarray(same_len, dtype=np.int64))
        spa = sim.steps_per_action
        for n, seq in enumerate(same_len):
            rows = sim.run(seq).rows
            last = int(rows[-1, L.M_STEP])
            played = -(-last // spa)  # actions that were (at least partly) played
            for k in range(len(seq)):
                if k >= played:
                    if not (np.isnan(batch.d_end[n, k]) and np.isnan(batch.v_end[n, k])):
                        raise DeterminismError(f"batch episode {n}, action {k}: played after the episode ended")
                    continue
                i = min((k + 1) * spa, last)  # row index = time step (row 0 is the initial state)
                if not (_same_bits(np.array([batch.d_end[n, k]]), rows[i:i + 1, L.M_D])
                        and _same_bits(np.array([batch.v_end[n, k]]), rows[i:i + 1, L.M_V])):
                    raise DeterminismError(f"batch episode {n}, action {k}: differs from run()")
            unsafe_row = rows[-1, L.M_UNSAFE] != 0.0
            expect = int(rows[-1, L.M_STEP]) if unsafe_row else -1
            if int(batch.unsafe_step[n]) != expect:
                raise DeterminismError(f"batch episode {n}: unsafe step {batch.unsafe_step[n]} != {expect}")
    return len(seqs)
