"""A self-crossing lathe profile and a self-crossing prism outline are refused at load with one
line naming the two segments that meet (a crossing outline has no consistent inside)."""
import pytest

from workbench.core.errors import WorkbenchError
from workbench.scene.kinds import lathe as L
from workbench.scene.kinds import prism as P

BOWTIE = [[0.5, 0.0], [1.0, 1.0], [0.2, 1.0], [1.2, 0.2]]


@pytest.mark.parametrize("points", [BOWTIE, [[0.5, 0.0], [1.0, 1.0], [0.75, 0.5]]],
                         ids=["crossing", "folding-back"])
def test_lathe_self_crossing_profile_refused(points):
    with pytest.raises(WorkbenchError) as e:
        L.read({"points": points}, "o", {"material": "m"})
    msg = str(e.value)
    assert "\n" not in msg and "crosses itself" in msg and "segment 0" in msg


def test_prism_self_crossing_outline_refused():
    with pytest.raises(WorkbenchError) as e:
        P.read({"polygon": [[0, 0], [1, 1], [1, 0], [0, 1]], "heights": [0, 1]}, "o", {"material": "m"})
    msg = str(e.value)
    assert "\n" not in msg and "not simple" in msg and "edge 0" in msg and "edge 2" in msg


def test_simple_profiles_accepted():
    L.read({"points": [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]}, "o", {"material": "m"})
    L.read({"points": [[0.5, 0.0], [1.0, 0.0], [1.0, 1.0], [0.5, 1.0], [0.5, 0.0]]}, "o", {"material": "m"})
    P.read({"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]], "heights": [0, 1]}, "o", {"material": "m"})
