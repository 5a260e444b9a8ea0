"""A fault's parameters are printed to what they mean: no float64 rounding digits, no fields that are not implied."""

from wirecheck.oracles.reports.fault_text import full_text as fault_text


def test_a_parameter_one_rounding_from_nominal_prints_as_nominal():
    # scale_y = 1 - 2 ulp: the aspect fault is on x; y's scale is 1 up to float64 rounding
    # (2 eps << the 64 eps floor), so it prints as 1, not 0.9999999999999998
    text = fault_text([{"name": "aspect_mismatch", "scale_x": 0.75, "scale_y": 1 - 2 * 2.0**-53}])
    assert text == "aspect_mismatch(scale_x=0.75, scale_y=1)"


def test_a_real_small_difference_keeps_its_digits():
    # 4e-7 from nominal is 1.8e9 eps: a measured difference, printed until it differs from 1
    assert fault_text([{"name": "fov_mismatch", "scale": 1.0000004}]) == "fov_mismatch(scale=1.0000004)"


def test_a_field_that_is_not_implied_is_left_out():
    text = fault_text([{"name": "fov_mismatch", "scale": 0.8, "implied_fov_deg": 72.5, "implied_ortho_height": None}])
    assert text == "fov_mismatch(scale=0.8, implied_fov_deg=72.5)"


def test_the_cli_shows_two_reasons_and_counts_the_rest():
    from wirecheck.oracles.reports.compared import reason_text

    reasons = [
        "max vertex error 289 px > 1e-06 px",
        "pixel F1@1px 0.0614 < 0.999",
        "pixel F1@0px 0.0117 < 0.98",
        "edge 9 has -193 pixels against the oracle's count",
    ]
    assert reason_text(reasons) == (
        "max vertex error 289 px > 1e-06 px; pixel F1@1px 0.0614 < 0.999; +2 more in report.md"
    )
    assert reason_text(reasons[:2]) == "max vertex error 289 px > 1e-06 px; pixel F1@1px 0.0614 < 0.999"
