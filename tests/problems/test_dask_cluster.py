"""A sweep and a dispersion on a Dask `LocalCluster` with two worker processes
(`client.get_executor()`): results identical to the serial runs."""
from __future__ import annotations

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")

from appdyn.problems import stability as st  # noqa: E402
from appdyn.problems.dispersion import Normal, dispersion, nutation_history, spinner  # noqa: E402

X0 = [0, 0, 0, 1, 0.0, 0.0, 1.0]
T = np.linspace(0.0, 10.0, 11)
SPIN = {"transverse_inertia": Normal(1000.0, 20.0), "axial_inertia": Normal(1500.0, 30.0),
        "w1": Normal(0.02, 0.004)}


@pytest.fixture(scope="module")
def executor():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=50)
    client = distributed.Client(cluster)
    try:
        yield client.get_executor()
    finally:
        client.close()
        cluster.close()


@pytest.mark.slow
def test_sweep_on_a_local_cluster_is_the_serial_sweep(executor):
    args = ("gyrostat", "wheel_momentum", np.linspace(-2, 8, 6))
    kw = dict(inertia=[3.0, 4.0, 5.0], axis=[1, 0, 0], rate=2.0)
    serial = st.sweep(*args, **kw)
    spread = st.sweep(*args, executor=executor, **kw)
    assert spread.verdicts == serial.verdicts and spread.boundaries == serial.boundaries
    assert np.array_equal(spread.eigenvalues, serial.eigenvalues, equal_nan=True)
    assert len(serial.boundaries) == 2


@pytest.mark.slow
def test_dispersion_on_a_local_cluster_is_the_serial_dispersion(executor):
    kw = dict(samples=6, seed=3, params=SPIN, outputs={"nutation": nutation_history})
    serial = dispersion(spinner, X0, T, **kw)
    spread = dispersion(spinner, X0, T, executor=executor, **kw)
    assert serial.success and spread.success
    for name in serial.inputs:
        assert np.array_equal(serial.inputs[name], spread.inputs[name])
    assert np.array_equal(serial.outputs["nutation"], spread.outputs["nutation"])
