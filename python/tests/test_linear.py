"""The linear model: state_space's matrices give frequency_response's complex
responses, C(jωI − A)⁻¹B + D, and frequency_response's paper ratio is the gain
`rtid experiment frequency-response --linear` writes."""

import numpy as np
import pytest

import rtid

# Within the paper's test band and about it (the solve of the 2n-state system for
# the comparison loses digits far above the modes: 2e-8 at 2.5 kHz).
FREQS = np.array([3.0, 47.5, 100.0, 186.9, 400.0, 612.0])


@pytest.mark.parametrize("preset", ["worm-gear", "roller-gear-cam"])
def test_the_state_space_gives_the_frequency_response(preset):
    p = rtid.params(preset)
    m = rtid.state_space(p)
    A, B, C, D = m
    n = A.shape[0]
    assert B.shape == (n, 2) and C.shape == (n, n) and D.shape == (n, 2)
    assert m.inputs == ["motor_torque", "table_torque"] and m.outputs == m.states
    assert m.states[: n // 2] == rtid.modes(p)["free_dofs"]
    for j, input in enumerate(m.inputs):
        for i, output in enumerate(m.outputs):
            h = rtid.frequency_response(p, FREQS, input=input, output=output)
            for f, hf in zip(FREQS, h):
                x = np.linalg.solve(2j * np.pi * f * np.eye(n) - A, B[:, j])
                expected = C[i] @ x + D[i, j]
                assert hf == pytest.approx(expected, rel=1e-9, abs=1e-300), (input, output, f)
    table, motor = m.states.index("theta_t"), m.states.index("theta_m")
    ratio = p["Rw"] * p.get("Rg", 1.0)
    h = rtid.frequency_response(p, FREQS)
    x = [np.linalg.solve(2j * np.pi * f * np.eye(n) - A, B[:, 0]) for f in FREQS]
    assert np.allclose(h, [xi[table] / (xi[motor] * ratio) for xi in x], rtol=1e-9, atol=0)
    compliance = rtid.frequency_response(p, FREQS, output="motor_compliance")
    assert np.allclose(compliance, [xi[motor] for xi in x], rtol=1e-9, atol=0)


def test_the_paper_ratio_is_the_cli_linear_gain(cli, tmp_path):
    cli("experiment", "frequency-response", "--preset", "worm-gear", "--linear", "--out", tmp_path)
    table = np.genfromtxt(tmp_path / "frequency_response.csv", delimiter=",", names=True, skip_header=1)
    h = rtid.frequency_response(rtid.params("worm-gear"), table["frequency_hz"])
    assert np.allclose(20 * np.log10(np.abs(h)), table["gain_db"], rtol=0, atol=1e-9)
    assert np.allclose(np.degrees(np.angle(h)), table["phase_deg"], rtol=0, atol=1e-9)


def test_a_scalar_frequency_gives_a_complex_number():
    p = rtid.params("worm-gear")
    h = rtid.frequency_response(p, 100.0)
    assert isinstance(h, (complex, np.complexfloating)) and abs(h) > 0
    assert h == rtid.frequency_response(p, [100.0])[0]
    with pytest.raises(ValueError, match="response to the motor.s torque"):
        rtid.frequency_response(p, [10.0], input="table_torque")


def test_more_frequencies_than_the_limit_are_refused_at_once():
    with pytest.raises(ValueError, match="freqs_hz: ask for 2.000e5 frequencies, over the limit of 100000"):
        rtid.frequency_response(rtid.params("worm-gear"), np.linspace(1.0, 1000.0, 200_000))
