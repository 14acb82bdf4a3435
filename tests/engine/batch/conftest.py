"""Shared fixtures of the batch tests.

``slow`` tests (the paper-sized Fig. 3B groups: 100 samples of 20 x 20 at
20 px per block) run only with ``MESOFORGE_SLOW=1``.
"""

import logging
import os

import pytest


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: long runs; set MESOFORGE_SLOW=1 to run them")


def pytest_collection_modifyitems(config, items):
    if os.environ.get("MESOFORGE_SLOW") == "1":
        return
    skip = pytest.mark.skip(reason="slow; set MESOFORGE_SLOW=1 to run")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)


@pytest.fixture(scope="session")
def dask_client():
    """One local cluster (2 worker processes, 1 thread each) for the batch tests."""
    from distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=None, silence_logs=logging.ERROR)
    client = Client(cluster)
    yield client
    client.close()
    cluster.close()
