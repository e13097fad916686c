import numpy as np
import pytest
from helpers import BUNDLED, ERD_ARMS

import kinelab


@pytest.fixture(scope="session")
def robots():
    """Every robot the cross-checks run on, loaded once."""
    return {name: kinelab.load(name) for name in BUNDLED + ERD_ARMS}


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
