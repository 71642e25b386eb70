"""The structure's matrices (jointcal.models.structure) against closed forms."""
import numpy as np

from jointcal.models.structure import can_spring


def test_can_spring_gives_the_can_its_own_frequency_and_damping_ratio():
    """sqrt(k_can / m_can) = 2 pi f_can and c_can / (2 sqrt(k_can m_can)) = zeta_can, per parameter set."""
    m, f, z = np.array([0.004, 0.01]), np.array([4000.0, 5500.0]), 0.02
    k, c = can_spring(m, f, z)
    np.testing.assert_allclose(np.sqrt(k / m) / (2 * np.pi), f, rtol=1e-14)
    np.testing.assert_allclose(c / (2 * np.sqrt(k * m)), z, rtol=1e-14)
