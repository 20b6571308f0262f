"""Tests for serialkin.viz.animate: GIF/MP4 bytes, frame count, atomic files."""

import io
import warnings

import numpy as np
import pytest
from PIL import Image

from serialkin.errors import InputError, InputTypeError, NotSupportedError
from serialkin.viz.animate import (
    AnimationOptions,
    animate_trajectory,
    ffmpeg_available,
    frame_indices,
    save_animation,
)


def _frames(data: bytes) -> int:
    return Image.open(io.BytesIO(data)).n_frames


def test_gif_bytes_and_frame_count(planar3):
    """A planar GIF starts with GIF89a and has one frame per configuration."""
    Q = np.linspace([0.0, 0.0, 0.0], [1.0, -0.8, 0.6], 7)
    data = animate_trajectory(planar3, Q, AnimationOptions(frames=True, dpi=40),
                              path_points=planar3.fk(Q)[:, :2, 3],
                              obstacles=[dict(center=[0.3, 0.6], radius=0.1)])
    assert data[:6] == b"GIF89a"
    assert _frames(data) == 7


def test_gif_3d_with_max_frames(spatial4):
    """A spatial robot animates in 3D; max_frames caps the frame count (first and last kept)."""
    Q = spatial4.random_q(12, seed=9)
    data = animate_trajectory(spatial4, Q, AnimationOptions(max_frames=5, dpi=40, title="spatial"))
    assert data[:6] == b"GIF89a" and _frames(data) == 5
    idx = frame_indices(12, 5)
    assert idx[0] == 0 and idx[-1] == 11 and len(idx) == 5
    np.testing.assert_array_equal(frame_indices(4, 10), np.arange(4))


def test_frames_show_the_motion(planar3):
    """Consecutive frames differ (the arm moves): the first and last images are not equal."""
    Q = np.linspace([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], 3)
    im = Image.open(io.BytesIO(animate_trajectory(planar3, Q, AnimationOptions(dpi=40))))
    first = np.asarray(im.convert("RGB")).copy()
    im.seek(2)
    last = np.asarray(im.convert("RGB"))
    assert (first != last).any(axis=-1).mean() > 0.005


def test_save_animation_atomic(tmp_path, planar3):
    """save_animation writes the file by its suffix and leaves no temporary file behind."""
    Q = np.linspace([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], 3)
    out = save_animation(planar3, Q, tmp_path / "sub" / "arm.gif", AnimationOptions(dpi=30))
    assert out.read_bytes()[:6] == b"GIF89a"
    assert [p.name for p in out.parent.iterdir()] == ["arm.gif"]
    with pytest.raises(InputError, match=r"\.gif or \.mp4"):
        save_animation(planar3, Q, tmp_path / "arm.avi")


def test_bad_arguments(planar3):
    """Unknown formats, empty or wrong-width trajectories and fps <= 0 are rejected."""
    Q = np.zeros((2, 3))
    with pytest.raises(InputError, match="fmt"):
        animate_trajectory(planar3, Q, fmt="avi")
    with pytest.raises(InputError, match="fps"):
        AnimationOptions(fps=0)
    with pytest.raises(InputError, match="q"):
        animate_trajectory(planar3, np.zeros((2, 4)))
    with pytest.raises(InputError, match="q must have shape"):
        animate_trajectory(planar3, np.zeros(3))


def test_mp4_when_ffmpeg_present(tmp_path, planar3):
    """With ffmpeg an MP4 (ISO base media, 'ftyp' box) is written; without, a clear error."""
    Q = np.linspace([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], 4)
    if not ffmpeg_available():
        with pytest.raises(NotSupportedError, match="ffmpeg"):
            animate_trajectory(planar3, Q, fmt="mp4")
        pytest.skip("ffmpeg not on PATH: MP4 output not exercised (the error was checked)")
    out = save_animation(planar3, Q, tmp_path / "arm.mp4", AnimationOptions(dpi=40))
    assert out.read_bytes()[4:8] == b"ftyp"


def test_progress_bar_counts_frames(planar3, capsys):
    """progress=True reports every rendered frame on stderr (tqdm)."""
    Q = np.linspace([0.0, 0.0, 0.0], [0.5, 0.5, 0.5], 4)
    data = animate_trajectory(planar3, Q, AnimationOptions(dpi=30, progress=True))
    assert _frames(data) == 4
    assert "4/4" in capsys.readouterr().err


def test_old_keyword_form_warns_and_gives_the_same_bytes(tmp_path, planar3):
    """Options given as keywords warn, naming AnimationOptions, and encode the same GIF."""
    Q = np.linspace([0.0, 0.0, 0.0], [1.0, -0.5, 0.4], 5)
    path = planar3.fk(Q)[:, :2, 3]
    with pytest.warns(DeprecationWarning, match=r"AnimationOptions\(\.\.\.\)") as caught:
        old = animate_trajectory(planar3, Q, path_points=path, dpi=30, max_frames=3,
                                 frames=True, title="t")
    assert caught[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        new = animate_trajectory(planar3, Q, AnimationOptions(dpi=30, max_frames=3,
                                                              frames=True, title="t"),
                                 path_points=path)
    assert old == new
    with pytest.warns(DeprecationWarning, match="save_animation"):
        saved = save_animation(planar3, Q, tmp_path / "old.gif", path_points=path, dpi=30,
                               max_frames=3, frames=True, title="t")
    assert saved.read_bytes() == new


def test_animation_options_check_their_fields(planar3):
    """AnimationOptions names the field, what it expects and what came; misuse is refused."""
    with pytest.raises(InputError, match="dpi must be >= 10, got 5"):
        AnimationOptions(dpi=5)
    with pytest.raises(InputError, match="max_frames must be >= 1, got 0"):
        AnimationOptions(max_frames=0)
    with pytest.raises(InputError, match=r"figsize must be \(width, height\).* got 5"):
        AnimationOptions(figsize=5)
    with pytest.raises(InputError, match=r"figsize\[1\] must be a finite number > 0"):
        AnimationOptions(figsize=(4.0, -1.0))
    with pytest.raises(InputTypeError, match="trace must be True or False, got 'yes'"):
        AnimationOptions(trace="yes")
    with pytest.raises(InputTypeError, match="planar must be True, False or None, got 2"):
        AnimationOptions(planar=2)
    with pytest.raises(InputTypeError, match="title must be a string or None, got int"):
        AnimationOptions(title=1)
    Q = np.zeros((2, 3))
    with pytest.raises(InputTypeError, match="unknown argument.*colour"):
        animate_trajectory(planar3, Q, colour="red")
    with pytest.raises(InputTypeError, match="got options and also fps"):
        animate_trajectory(planar3, Q, AnimationOptions(), fps=3)
    with pytest.raises(InputTypeError, match="options must be an AnimationOptions or None"):
        animate_trajectory(planar3, Q, {"fps": 3})
    with pytest.raises(InputError, match="fmt contradicts the suffix"):
        save_animation(planar3, Q, "arm.gif", fmt="mp4")
