"""Errors as Python has them: TypeError for a wrong type, ValueError naming the
argument for a wrong value, a misspelt name refused with the closest known one, and
no message naming the temporary files the arrays are checked through."""

import numpy as np
import pytest

import rtid

FR = dict(frequency_hz=np.array([10.0, 20.0, 30.0]), gain_db=np.array([0.0, 1.0, 2.0]))


@pytest.mark.parametrize("call, argument", [
    (lambda: rtid.simulate(rtid.params("worm-gear"), "none", duration_s="1"), "duration_s"),
    (lambda: rtid.simulate(rtid.params("worm-gear"), "none", 0.01, sample_s=[1e-4]), "sample_s"),
    (lambda: rtid.params("worm-gear", Kw="stiff"), "Kw"),
    (lambda: rtid.params(3), "preset"),
    (lambda: rtid.experiment("frequency_response", conditions=[("averages", 4)], **FR), "conditions"),
    (lambda: rtid.experiment(1, **FR), "kind"),
    (lambda: rtid.identify("x.json", rtid.params("worm-gear"), starts=2.5), "starts"),
    (lambda: rtid.identify("x.json", rtid.params("worm-gear"), fit=3), "fit"),
    (lambda: rtid.identify(3.0, rtid.params("worm-gear")), "experiments"),
    (lambda: rtid.sweep(rtid.params("worm-gear"), "Kw=1e5..1e6:3", "resonances", samples="8"), "samples"),
    (lambda: rtid.frequency_response(rtid.params("worm-gear"), [10.0], input=1), "input"),
])
def test_a_wrong_type_raises_type_error_naming_the_argument(call, argument):
    with pytest.raises(TypeError, match=argument):
        call()


@pytest.mark.parametrize("call, message", [
    (lambda: rtid.params("worm-gear", pth="p.json"), "pth.*did you mean `path`"),
    (lambda: rtid.params("worm-gear", kw=3e5), "kw.*did you mean `Kw`"),
    (lambda: rtid.params("worm-gear", Kwm=3e5), "Kwm.*did you mean `Kw`"),
    (lambda: rtid.experiment("frequency_response", phase_degs=np.zeros(3), **FR),
     "phase_degs.*did you mean `phase_deg`"),
    (lambda: rtid.experiment("frequency_response", conditions={"preload": 2.0}, **FR),
     "conditions: unknown condition `preload`; did you mean `preload_nm`"),
    (lambda: rtid.experiment("frequency_respons", **FR), "did you mean `frequency_response`"),
    (lambda: rtid.identify("x.json", rtid.params("worm-gear"), fit=["Kw", "Kgg"]), "fit.*Kgg.*`Kg`"),
    (lambda: rtid.identify("x.json", rtid.params("worm-gear"), model="linaer"), "model.*`linear`"),
    (lambda: rtid.frequency_response(rtid.params("worm-gear"), [10.0], output="theta_x"), "output"),
])
def test_a_misspelt_name_is_refused_with_the_closest_known(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_an_empty_fit_is_refused(root):
    with pytest.raises(ValueError, match="fit: an empty list"):
        rtid.identify(root / "fixtures/worm-gear/frequency_response.json", rtid.params("worm-gear"),
                      fit=[], model="linear")


def test_an_extra_column_of_its_own_name_is_kept():
    exp = rtid.experiment("frequency_response", contact_loss_drive=np.zeros(3), **FR)
    assert set(exp.columns) == {"frequency_hz", "gain_db", "contact_loss_drive"}


@pytest.mark.parametrize("kwargs, expected", [
    (dict(frequency_hz=np.array([10.0, 30.0, 20.0]), gain_db=np.zeros(3)),
     "experiment 'sine test', row 2 of the columns"),
    (dict(conditions={"delay_s": "late"}, **FR), "the manifest of experiment 'sine test'"),
])
def test_messages_name_the_experiment_not_a_temporary_file(kwargs, expected):
    with pytest.raises(ValueError) as e:
        rtid.experiment("frequency_response", name="sine test", **kwargs)
    text = str(e.value)
    assert expected in text
    assert "rtid-" not in text and ".json" not in text and ".csv" not in text, text


def test_inputs_the_model_cannot_resolve_are_refused():
    # A sine above the Nyquist frequency of the step, a control period longer than the
    # drive's slowest mode (10 s for 10 ms): refused, as on the command line.
    p = rtid.params("worm-gear")
    with pytest.raises(ValueError, match="a sine of 1e9 Hz.*Nyquist frequency 50000 Hz"):
        rtid.simulate(p, "sine:freq_hz=1e9,amp_nm=5", duration_s=0.01)
    slow = rtid.params("worm-gear", Tc=10.0)
    with pytest.raises(ValueError, match="control period Tc = 10 s.*slowest mode"):
        rtid.simulate(slow, "move:target_deg=1", duration_s=0.01)
    with pytest.raises(ValueError, match="control period Tc = 10 s"):
        rtid.run_experiment("torque-curve", slow)


@pytest.mark.parametrize("call, error, message", [
    (lambda: rtid.sweep(rtid.params("worm-gear"), "Kww=1e5..1e6:3", "resonances"), ValueError,
     "vary: unknown parameter `Kww`; did you mean `Kw`"),
    (lambda: rtid.identify("x.json", rtid.params("worm-gear"), fit="Kw", bounds={"Kw": 5.0}), TypeError,
     r"bounds\[Kw\]: expected a pair \(low, high\)"),
    (lambda: rtid.frequency_response(rtid.params("worm-gear"), "100"), TypeError, "freqs_hz"),
    (lambda: rtid.run_experiment("positioning", rtid.params("worm-gear"), travel_mm=100.0), ValueError,
     "travel_mm: for a linear axis"),
    (lambda: rtid.run_experiment("positioning", rtid.params("worm-gear"), target_step_deg=0.01), ValueError,
     "target_step_deg.*over 1000 targets"),
    (lambda: rtid.run_experiment("servo_trace", rtid.params("direct-drive"), moves="0.1@"), ValueError, "moves"),
    (lambda: rtid.run_experiment("friction_map", rtid.params("direct-drive"), speeds_rpm=[0.0]), ValueError,
     "speeds_rpm: 0 is not a speed"),
    (lambda: rtid.tune(rtid.params("worm-gear"), phase_margin_deg=200.0), ValueError, "phase_margin_deg"),
    (lambda: rtid.predict({"parameters": {}}, rtid.params("worm-gear"), draws=3), ValueError, "fit"),
    (lambda: rtid.compensate(rtid.params("worm-gear"), runs="3-1"), ValueError, "runs"),
    (lambda: rtid.evaluate("fixtures/worm-gear/torque_curve.json", runs="1-2"), ValueError,
     "for positioning records"),
])
def test_the_commissioning_calls_name_what_is_wrong(root, monkeypatch, call, error, message):
    monkeypatch.chdir(root)
    with pytest.raises(error, match=message):
        call()


def test_a_decreasing_frequency_names_the_row_and_its_value():
    f = np.arange(10.0, 410.0)
    f[-2] = f[-3] - 1.0
    with pytest.raises(ValueError) as e:
        rtid.experiment("frequency_response", frequency_hz=f, gain_db=np.zeros(f.size), name="sweep")
    text = str(e.value)
    assert "row 398 of the columns" in text and "the previous row's value: 407" in text, text
