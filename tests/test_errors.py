"""One exception tree: every error upperpose raises on purpose is an UpperposeError."""

from __future__ import annotations

import numpy as np
import pytest

import upperpose
from upperpose.exceptions import InputError, SearchError, UpperposeError, VideoError


def test_the_tree() -> None:
    assert issubclass(InputError, UpperposeError) and issubclass(InputError, ValueError)
    assert issubclass(SearchError, UpperposeError) and issubclass(VideoError, UpperposeError)
    assert not issubclass(SearchError, ValueError)
    assert upperpose.UpperposeError is UpperposeError


@pytest.mark.parametrize(
    "call",
    [
        lambda: upperpose.Camera.for_image(0, 480),
        lambda: upperpose.SearchConfig(particles=0),
        lambda: upperpose.BodyModel(shoulder_width=float("nan")),
        lambda: upperpose.forward_kinematics(np.zeros(12), [0, 0, 2]),
        lambda: upperpose.render_masks(upperpose.Pose(), [0.0, 0.0, 2.0], upperpose.Camera.for_image(64, 48), 0, 48),
    ],
)
def test_core_and_binding_errors_are_input_errors(call) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(InputError) as caught:
        call()
    assert str(caught.value)
