"""``tools.contact_problems``: a run's one-step problems kept and solved again.

The replay is the instrument docs/reference-solver-speed.md measures the hybrid chain's changes
with, so it must give back, on the checkout that recorded them, exactly what the run's own
(Python) chain returned: the compiled chain is the same sequence of attempts on the same
kernels, its "Newton first" memory carried from problem to problem as in the run.
"""

from __future__ import annotations

import numpy as np

from tools.contact_problems import problems, record, recorded_options, replay


def test_a_recording_replays_to_the_bit_on_its_own_checkout(tmp_path):
    data = record("clearance-pendulum", None, 0, 60)
    np.savez_compressed(tmp_path / "p.npz", **data)
    with np.load(tmp_path / "p.npz") as handle:
        loaded = {name: handle[name] for name in handle.files}
    cases = problems(loaded)
    assert len(cases) == loaded["rows"].size > 0
    for (_, W, q, mu, nb, r0, r), m in zip(cases, loaded["rows"], strict=True):
        assert W.shape == (m, m) and q.shape == r0.shape == r.shape == (m,)
        assert mu.size == (m - nb) // 3
    replayed = replay(loaded)
    assert replayed["equal"] == len(cases)
    assert replayed["largest_velocity_difference"] == 0.0
    np.testing.assert_array_equal(replayed["iterations"], loaded["iterations"])
    np.testing.assert_array_equal(replayed["converged"], loaded["converged"])


def test_a_recording_keeps_its_engine_options_and_replays_with_them(tmp_path):
    """Problems recorded under ``activation=held`` are solved again under the same settings:
    the file names the options, and the replay gives back the recorded results to the bit."""
    data = record("clearance-pendulum", None, 0, 40, {"activation": "held"})
    np.savez_compressed(tmp_path / "p.npz", **data)
    with np.load(tmp_path / "p.npz") as handle:
        loaded = {name: handle[name] for name in handle.files}
    assert recorded_options(loaded) == {"activation": "held"}
    replayed = replay(loaded)
    assert replayed["equal"] == loaded["rows"].size > 0


def test_every_candidate_solves_a_sliding_contact():
    """One contact, W = I (m/s per N s), q = (-1, 0.5, 0) m/s, mu = 0.3: the Coulomb solution
    slides, r = (1, -0.3, 0) N s with u = (0, 0.2, 0) m/s (u_N = 0 closes the contact; the
    stick impulse 0.5 exceeds mu r_N = 0.3). Each candidate must find it to 1e-10 N s: on a
    problem of unit scale the residual tolerance (1e-12) bounds the error far below that."""
    from clearbench.ref_solver.compiled.system_arrays import compile_system
    from tools.contact_problems import _model
    from tools.solve_candidates import DEFAULT_CANDIDATES, run_candidate

    _, cfg = compile_system(_model("clearance-pendulum", None).stepper)
    case = (1, np.eye(3), np.array([-1.0, 0.5, 0.0]), np.array([0.3]), 0, np.zeros(3),
            np.zeros(3))
    for name in (*DEFAULT_CANDIDATES, "admm", "newton>chain",
                 "newton>prox:1e-6:50:from-newton>chain"):
        out = run_candidate(name, [case], cfg)
        assert out["converged"].all(), name
        np.testing.assert_allclose(out["results"][0], [1.0, -0.3, 0.0], atol=1e-10,
                                   err_msg=name)
