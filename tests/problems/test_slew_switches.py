"""`slew.switch_times` is the engine's switch detector; `plot_slew` builds a Figure."""
import numpy as np
import pytest
from matplotlib.figure import Figure

from appdyn import ocp
from appdyn.problems import slew


@pytest.fixture(scope="module")
def bilimoria_wie():
    return slew.time_optimal(np.eye(3), angle=np.pi, axis=[0, 0, 1], u_max=1.0)


def test_switch_times_agree_with_the_engine(bilimoria_wie):
    sol = bilimoria_wie
    assert sol.success, sol.message
    per = slew.switch_times(sol)
    assert len(per) == 3
    for a, b in zip(per, ocp.control_switches(sol)):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_allclose(np.unique(np.concatenate(per)), ocp.find_switches(sol), atol=1e-9)
    np.testing.assert_array_equal(slew.switch_times(sol, axis=2), per[2])
    assert slew.summary(sol)["switch_times"] == [s.tolist() for s in per]
    with pytest.raises(ValueError, match="`axis`"):
        slew.switch_times(sol, axis=3)


def test_plot_slew_returns_a_figure_and_saves_on_request(bilimoria_wie, tmp_path):
    fig = slew.plot_slew(bilimoria_wie)
    assert isinstance(fig, Figure) and len(fig.axes) == 4
    out = tmp_path / "slew.png"
    fig2 = slew.plot_slew(bilimoria_wie, out)
    assert isinstance(fig2, Figure) and out.stat().st_size > 0
    with pytest.raises(TypeError, match="`fig`"):
        slew.plot_slew(bilimoria_wie, fig="figure")


def test_switch_times_component_and_the_deprecated_axis(bilimoria_wie):
    sol = bilimoria_wie
    per = slew.switch_times(sol)
    np.testing.assert_array_equal(slew.switch_times(sol, component=1), per[1])
    with pytest.warns(DeprecationWarning, match="component"):
        np.testing.assert_array_equal(slew.switch_times(sol, axis=1), per[1])
    with pytest.raises(ValueError, match="`component`"):
        slew.switch_times(sol, component=3)
    with pytest.raises(TypeError, match="`component`"):
        slew.switch_times(sol, component=[0, 0, 1])
    with pytest.raises(TypeError, match="not both"):
        slew.switch_times(sol, component=1, axis=1)
