"""Did-you-mean: close names, case ignored, shortened names, nothing when nothing is close."""

from simgap.suggest import close_names, did_you_mean


def test_close_names():
    names = ["T_zone", "T_water", "UA_env", "P_el", "Q_int"]
    assert close_names("t_zone", names) == ["T_zone"]
    assert close_names("UA_envelope", names) == ["UA_env"]
    assert close_names("P_electric", names) == ["P_el"]
    assert close_names("humidity", names) == []


def test_did_you_mean_wording():
    assert did_you_mean("sede", ["seed", "plugin"]) == " (did you mean 'seed'?)"
    assert did_you_mean("sede", ["seed"], inside_parentheses=True) == "; did you mean 'seed'?"
    assert did_you_mean("zzz", ["seed"]) == ""
