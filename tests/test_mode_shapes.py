"""Mode shapes drawn on the structure (``rt70 modes SCENE --plot FILE``)."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from rt70.cli.main import main
from rt70.linear import linearize as lin
from rt70.linear import modal
from rt70.linear.mode_shapes import DRAWN_FRACTION, DRAWN_RTOL, draw_modes, structure_lines
from rt70.model.scene import scene_from_text
from rt70.scenes.beam_scenes import beam_text

PHASES = np.linspace(0.0, 2 * np.pi, 8, endpoint=False)


@pytest.fixture(scope="module")
def cantilever():
    """A 2 m cantilever along ground x in 4 segments, its linear model and modes."""
    scene = scene_from_text(beam_text(4, extra='axial="false"'))
    q0 = np.zeros(len(scene.coordinate_names))
    lm = lin.linearize(scene, q0)
    return scene, lm, modal.modes(lm.M, lm.K)


def test_the_structure_is_the_tree_of_frames_and_centres_of_mass(cantilever):
    scene, _, _ = cantilever
    lines = structure_lines(scene)
    frames = [name for name, xyz in lines.points if not xyz.any()]
    assert {"world", "b_seg0", "b_seg4", "b_end"} <= set(frames)
    massive = [s for s in scene.description.links.values() if s.inertial and s.inertial.mass > 0]
    assert len(lines.points) == len(frames) + len(massive)  # each rfe's centre is off its frame
    assert len(lines.segments) == len(lines.points) - 1  # a tree: one segment per point but one


def test_a_mode_moves_the_structure_by_the_drawn_fraction_of_its_size(cantilever):
    scene, lm, result = cantilever
    lines, rest, drawn = draw_modes(
        scene, lm.q0, lm.coordinates, result.shapes[:, :3], ["a", "b", "c"], PHASES
    )
    end = next(i for i, (name, xyz) in enumerate(lines.points) if name == "b_end")
    assert rest[end] == pytest.approx([2.0, 0.0, 0.0], abs=1e-12)
    size = np.linalg.norm(np.ptp(rest, axis=0))
    for mode in drawn:
        assert np.array_equal(mode.positions[0], rest)  # sin 0 = 0: at rest, exactly
        assert mode.peak == pytest.approx(DRAWN_FRACTION * size, rel=2 * DRAWN_RTOL)
    first = drawn[0].positions[2] - rest  # φ = π/2
    moved = np.linalg.norm(first, axis=1)
    assert np.argmax(moved) == end or moved[end] == pytest.approx(moved.max(), rel=1e-9)


def test_modes_plot_writes_a_figure_and_an_animation(tmp_path, capsys):
    urdf = tmp_path / "mast.urdf"
    urdf.write_text(beam_text(3, extra='axial="false"'))
    png, gif = tmp_path / "modes.png", tmp_path / "modes.gif"
    assert main(["modes", str(urdf), "--plot", str(png), "--plot-modes", "2"]) == 0
    assert f"wrote {png}" in capsys.readouterr().out
    with Image.open(png) as image:
        assert image.format == "PNG" and image.size[0] > 500
    assert main(["modes", str(urdf), "--plot", str(gif), "--plot-modes", "2"]) == 0
    with Image.open(gif) as image:
        assert image.format == "GIF" and image.n_frames == 24


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--plot", "modes.txt"], "--plot must be a .png, .pdf, .svg, .gif file"),
        (["--plot", "m.png", "--plot-modes", "0"], "--plot-modes"),
    ],
)
def test_bad_plot_options_are_refused_before_any_work(tmp_path, capsys, extra, message):
    extra = [str(tmp_path / e) if e.endswith((".txt", ".png")) else e for e in extra]
    try:
        code = main(["modes", "no-such-scene", *extra])
    except SystemExit as stop:  # argparse's own refusals
        code = stop.code
    err = capsys.readouterr().err
    assert code == 2 and message in err and "no-such-scene" not in err  # before reading it
    assert len(err.strip().splitlines()) == 1
