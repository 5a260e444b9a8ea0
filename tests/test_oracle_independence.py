"""The oracles build their own camera basis: a wrong ``right`` in core cannot leak into them."""

from types import SimpleNamespace

import numpy as np
from wirecheck.core.camera import look_at
from wirecheck.oracles.references import opencv_oracle


def test_opencv_oracle_ignores_a_reversed_right():
    cam = look_at((3, 2, 4), (0, 0, 0), (0.3, 1.0, 0.1), fov_y_deg=55)
    spec = {
        k: getattr(cam, k)
        for k in (
            "position",
            "forward",
            "up",
            "fov_y_deg",
            "width",
            "height",
            "near",
            "far",
            "projection",
            "ortho_height",
        )
    }
    liar = SimpleNamespace(**spec, right=-cam.right)  # as if core's cross product were reversed
    pts = np.random.default_rng(3).uniform(-1, 1, (50, 3))
    # identical inputs to the oracle's arithmetic: bitwise equal output
    np.testing.assert_array_equal(opencv_oracle.project(pts, liar), opencv_oracle.project(pts, cam))
