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
