"""`benchmark publish mtf50-isp` makes docs/data/mtf50-isp.csv and the table of docs/camera.md,
"MTF50 on ISETCam's terms", from the cameras and ISETCam's curves."""

from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

from benchmark.publish import mtf50_isp

REPO = Path(__file__).resolve().parents[1]
PUBLISHED = REPO / "docs" / "data" / "mtf50-isp.csv"


def test_isetcam_curve_is_read_at_the_pixel_and_linear_in_f_number():
    assert mtf50_isp.isetcam_curve(1.4, 3.0) == 131.0
    assert mtf50_isp.isetcam_curve(1.4, 3.3) == pytest.approx(131.0 + 0.15 * (103.8 - 131.0))
    assert mtf50_isp.isetcam_curve(4.2, 11.0) == 40.4
    with pytest.raises(ValueError, match="no ISETCam curve for 2.0"):
        mtf50_isp.isetcam_curve(2.0, 2.0)


def test_the_published_table_is_what_the_command_makes(tmp_path):
    from benchmark.cli.main import app

    out = tmp_path / "mtf50-isp.csv"
    result = CliRunner().invoke(app, ["publish", "mtf50-isp", "--out", str(out)])
    assert result.exit_code == 0, result.output
    made, published = pd.read_csv(out), pd.read_csv(PUBLISHED)
    assert list(made.columns) == list(published.columns) and list(made["camera"]) == list(published["camera"])
    # (to the last digit printed: an AVX-512 machine's kernels may move one)
    pd.testing.assert_frame_equal(made, published, check_exact=False, atol=0.011, rtol=0)
    page = (REPO / "docs" / "camera.md").read_text().splitlines()
    rows = mtf50_isp.markdown(published).splitlines()[2:]  # (below the header and its rule)
    assert len(rows) == 13 and [row for row in rows if row not in page] == []
    assert result.output.strip() == mtf50_isp.markdown(made)


def test_a_camera_without_a_published_group_is_refused_before_measuring():
    from benchmark.cli.main import app

    result = CliRunner().invoke(app, ["publish", "mtf50-isp", "--cameras", "cam12,cameras/tutorial-2.0um-f1.8-6mm.yaml"])
    assert result.exit_code == 2 and "no published MTF50 group" in result.output and "| cam12 |" not in result.output
