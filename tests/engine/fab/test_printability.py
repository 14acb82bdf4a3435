import numpy as np
import pytest

from engine.fab import Layer, printability, split_path

W = 0.4


def line(y, x0=0.0, x1=8.0):
    return np.array([[x0, y], [x1, y]])


def layer(z, *paths):
    return Layer(z=z, paths=tuple(paths), kinds=("infill",) * len(paths))


def test_first_layer_sits_on_the_bed_and_identical_layers_are_supported():
    rep = printability([layer(0.2, line(0)), layer(0.4, line(0)), layer(0.6, line(0))])
    assert rep.overhang_count == 0 and rep.overlap_count == 0
    assert rep.support.min() > 0.99
    assert set(rep.segment_layer.tolist()) == {0, 1, 2}
    assert rep.segment_length.sum() == pytest.approx(3 * 8.0)


def test_path_shifted_by_one_nozzle_overhangs_along_its_length():
    rep = printability([layer(0.2, line(0)), layer(0.4, line(W))])
    assert rep.overhang_per_layer.tolist() == [0, 1]
    assert rep.overhang_segments == pytest.approx([8.0])
    assert rep.support[rep.segment_layer == 1].max() < 0.4
    # half a nozzle sideways keeps half the bead on the wall below
    half = printability([layer(0.2, line(0)), layer(0.4, line(W / 2))])
    assert half.overhang_count == 0
    assert half.support[half.segment_layer == 1].mean() == pytest.approx(0.5, abs=0.03)


@pytest.mark.parametrize("spacing, overlaps, width", [(0.5, True, 0.5 * W), (1.0, False, 0.0),
                                                      (0.8, True, 0.2 * W)])
def test_parallel_paths_overlap_below_one_nozzle_spacing(spacing, overlaps, width):
    rep = printability([layer(0.2, line(0), line(spacing * W))])
    second = rep.segment_path == 1
    assert (rep.overlap_count == 1) == overlaps
    assert rep.overlap_width[second].mean() == pytest.approx(width, abs=0.04)
    assert not rep.overlap[~second].any()          # the first path meets nothing


def test_a_loop_does_not_overlap_itself_and_runs_join_across_its_seam():
    # seam (start = end) in the middle of the bottom side
    sq = np.array([[3.0, 0], [6, 0], [6, 6], [0, 6], [0, 0], [3, 0]])
    shifted = sq + (0.0, W)
    rep = printability([layer(0.2, sq), layer(0.4, sq), layer(0.6, shifted)])
    assert rep.overlap_count == 0
    # both horizontal sides of the shifted square hang off; the bottom one
    # rests on the walls below for one piece at each end, and is one
    # segment although it crosses the seam
    assert rep.overhang_per_layer.tolist() == [0, 0, 2]
    # (lengths are known to within one piece, which depends on where cuts fall)
    assert sorted(rep.overhang_segments) == pytest.approx([6.0 - 2 * W, 6.0], abs=W + 0.01)


def test_histograms_count_the_violating_segments():
    paths = [layer(0.2, line(0, 0, 3), line(2, 0, 8))]
    paths.append(layer(0.4, line(W, 0, 3), line(2 + W, 0, 8)))
    rep = printability(paths, bins=None)
    assert rep.overhang_histogram.sum() == rep.overhang_count == 2
    assert rep.bin_edges[0] == 0.0 and rep.bin_edges[-1] >= 8.0
    assert np.allclose(np.diff(rep.bin_edges)[:-1], W)
    assert rep.overlap_histogram.sum() == 0


def test_split_path_pieces():
    path = np.array([[0.0, 0], [1.0, 0], [1.0, 1.05], [1.0, 1.05]])
    pts, starts, lengths = split_path(path, 0.4)
    assert len(lengths) == 5 and lengths.sum() == pytest.approx(2.05)
    assert np.allclose(lengths, 0.41)
    for q in range(5):
        piece = pts[starts[q]:starts[q + 1]]
        assert np.hypot(*np.diff(piece, axis=0).T).sum() == pytest.approx(lengths[q])


def test_bad_options_are_named():
    with pytest.raises(ValueError, match="pixel_size"):
        printability([layer(0.2, line(0))], pixel_size=0)
    with pytest.raises(ValueError, match="min_support"):
        printability([layer(0.2, line(0))], min_support=2)
