"""The settings file: TOML in, TrackerConfig out, and back; `upperpose config`; `track --config`."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from upperpose.cli import main
from upperpose.features import FeatureConfig
from upperpose.fit import TrackerConfig
from upperpose.fit.settings import config_from_toml, config_to_dict, config_to_toml, load_config


def test_defaults_round_trip() -> None:
    text = config_to_toml(TrackerConfig())
    back = config_from_toml(text)
    # The printed file spells out the feature defaults; the tracker treats both alike.
    assert back == TrackerConfig(features=FeatureConfig())
    assert "# particles: not set" in text
    assert "\n[features]\n" in text and "\n[features.bg_person]\n" in text


@settings(max_examples=60, deadline=None)
@given(
    particles=st.none() | st.integers(1, 500),
    seed=st.integers(0, 2**40),
    share=st.floats(0.0, 1.0),
    scales=st.lists(st.floats(0.5, 1.5), max_size=5),
    sub_threshold=st.integers(0, 255),
    head_centre=st.floats(0.1, 0.9),
    edge=st.floats(0.0, 10.0),
)
def test_any_config_round_trips(particles, seed, share, scales, sub_threshold, head_centre, edge) -> None:  # type: ignore[no-untyped-def]
    features = FeatureConfig(sub_threshold=sub_threshold)
    features = dataclasses.replace(features, bg_person=dataclasses.replace(features.bg_person, head_centre=head_centre))
    config = TrackerConfig(
        particles=particles,
        seed=seed,
        presence_share=share,
        startup_width_scales=tuple(scales),
        features=features,
        search_options={"weights": {"edge": edge}},
    )
    assert config_from_toml(config_to_toml(config)) == config


def test_unknown_and_mistyped_settings_are_named() -> None:
    with pytest.raises(ValueError, match="unknown setting 'particels'"):
        config_from_toml("particels = 3")
    with pytest.raises(ValueError, match="lost_frames must be an integer"):
        config_from_toml('lost_frames = "five"')
    with pytest.raises(ValueError, match="features: sub_threshold must be an integer"):
        config_from_toml("[features]\nsub_threshold = 1.5")
    with pytest.raises(ValueError, match="skip_static must be true or false"):
        config_from_toml("skip_static = 1")
    with pytest.raises(ValueError, match="not valid TOML"):
        config_from_toml("particles = = 3")


def test_file_values_and_command_line_over_them(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "s.toml"
    path.write_text("particles = 40\nseed = 5\nlost_frames = 9\n[search.weights]\nedge = 2.5\n")
    config = load_config(path)
    assert (config.particles, config.seed, config.lost_frames) == (40, 5, 9)
    assert config.search_config().particles == 40 and config.search_config().seed == 5
    assert main(["config", "--config", str(path), "--seed", "7"]) == 0
    printed = config_from_toml(capsys.readouterr().out)
    assert (printed.particles, printed.seed, printed.lost_frames) == (40, 7, 9)
    assert printed.search_options == {"weights": {"edge": 2.5}}


def test_config_reports_a_bad_file_in_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "bad.toml"
    path.write_text("velocity_damping = [1, 2]\n")
    assert main(["config", "--config", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "velocity_damping must be a number" in err


def test_pose_file_settings_read_back() -> None:
    config = TrackerConfig(particles=30, features=FeatureConfig(edge_blur=5))
    as_dict = config_to_dict(config)
    assert as_dict["particles"] == 30 and as_dict["features"]["edge_blur"] == 5
    assert as_dict["iterations"] is None


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("lost_frames", -1, "lost_frames must be an integer >= 0, got -1"),
        ("confirm_frames", 0, "confirm_frames must be an integer >= 1"),
        ("presence_share", float("nan"), "presence_share must be a finite number >= 0 and <= 1"),
        ("velocity_damping", 1.5, "velocity_damping must be a finite number >= 0 and <= 1"),
        ("lost_threshold", 0.0, "lost_threshold must be a finite number > 0"),
        ("particles", -1, "particles must be an integer >= 1"),
        ("seed", -1, "seed must be an integer >= 0"),
        ("seed", 2**64, "seed must be below 2\\*\\*64"),
        ("startup_width_scales", (1.0, float("inf")), r"startup_width_scales\[1\] must be a finite number > 0"),
        ("leave_frames", 2.5, "leave_frames must be an integer"),
    ],
)
def test_tracker_config_checks_its_ranges(field: str, value: object, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        TrackerConfig(**{field: value})  # type: ignore[arg-type]
