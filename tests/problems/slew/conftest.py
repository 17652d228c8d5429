"""Shared settings of the scene-slew tests."""


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: a long case (deselect with -m 'not slow')")
