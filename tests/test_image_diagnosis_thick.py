"""oracles.diagnosis.image_diagnose on drawings other than 1-px aliased lines: no false faults, and faults still named.

Split from tests/test_image_diagnosis.py (which draws and diagnoses the
faults, and holds the drawing helpers) so that ``pytest -n 2 --dist loadfile``
can run it beside that file's long module fixture.
"""

from __future__ import annotations

import pytest
from test_image_diagnosis import MAIN_CAMERAS, diagnose_fault, draw_aa, draw_wide
from wirecheck.oracles.diagnosis.diagnose import primary
from wirecheck.oracles.tolerances import OFFSET_TOL_PX

pytestmark = pytest.mark.slow  # ~1 s per diagnosis of six images


# ---- drawings other than 1-px aliased lines: no false faults -----------------


@pytest.mark.parametrize("draw", [draw_aa, draw_wide], ids=["antialiased", "2px"])
@pytest.mark.parametrize("camera_name", MAIN_CAMERAS)
def test_thick_correct_lines_are_no_fault(draw, camera_name, summary_section):
    got = diagnose_fault("none", camera_name, draw=draw)
    assert got == [], got


@pytest.mark.parametrize("draw", [draw_aa, draw_wide], ids=["antialiased", "2px"])
def test_thick_lines_keep_their_faults(draw):
    # the faults are still named through thick lines, the half-pixel offset to 0.06 px
    # (a thick line's pixels are symmetric about it only on average)
    assert primary(diagnose_fault("mirror_x", "oblique", draw=draw)) == "mirror_horizontal"
    (f,) = diagnose_fault("offset", "oblique", draw=draw)
    assert f["name"] == "pixel_offset"
    assert f["dy"] == pytest.approx(0.5, abs=0.06)  # measured 0.46-0.52 through thick lines
    assert OFFSET_TOL_PX < 0.5 - 0.06  # so the offset could not hide under the tolerance
