"""The video tracker's quality file, imported_quality.nc (ballbat.stages.quality; docs/video.md)."""

from __future__ import annotations

import numpy as np
import pytest
from video_clips import quality_clip, quality_table

from ballbat.pipeline.checked import DamagedFileError
from ballbat.pipeline.ncio import MetadataError, read_dataset, write_dataset
from ballbat.stages.quality import QUALITY_TABLE, quality_columns, quality_dataset


@pytest.fixture(scope="module")
def table() -> dict:
    """A small quality table: three impacts' clips in both cameras (video_clips.quality_table)."""
    return quality_table()


def test_the_quality_file_holds_the_table_with_units_and_provenance(table, tmp_path):
    path = write_dataset(
        quality_dataset(table), tmp_path / "imported_quality.nc", title="t", rule="import_clips", inputs={}, config={}
    )
    ds = read_dataset(path, require=tuple(QUALITY_TABLE))
    assert ds.attrs["provenance_rule"] == "import_clips" and ds.attrs["n_clips"] == 6
    assert ds.attrs["n_found"] + ds.attrs["n_left_out"] == ds.attrs["n_rows"] == table["frame"].size
    assert ds["residual_px"].attrs["units"] == "1" and "pixels" in ds["residual_px"].attrs["long_name"]
    back = quality_columns(ds)
    for k in QUALITY_TABLE:
        if back[k].dtype.kind == "f":
            np.testing.assert_array_equal(back[k], table[k])
        else:
            assert list(back[k]) == list(table[k]), k


def test_a_file_that_is_not_a_quality_table_is_named(tmp_path):
    ds = quality_dataset(quality_clip("W1", "spin", 3, 0)).drop_vars("contrast")
    path = write_dataset(ds, tmp_path / "q.nc", title="t", rule="r", inputs={}, config={})
    with pytest.raises(MetadataError, match=r"q\.nc: missing variable\(s\) contrast"):
        read_dataset(path, require=tuple(QUALITY_TABLE))
    path.write_bytes(path.read_bytes()[:100])
    with pytest.raises(DamagedFileError, match=r"q\.nc"):
        read_dataset(path, require=tuple(QUALITY_TABLE))
