"""Kinetic energy along a trajectory: E_k = 1/2 qdot_k^T M(q_k) qdot_k per body.

``get_mass_matrix`` takes K configurations of n bodies in one request and
answers (K, n, 6, 6) without touching the node's state; the same energies
from K single-configuration calls measure what batching saves.
:func:`energy_from_inertia` is an independent oracle from ``get_bodies``
alone: E = 1/2 omega^T (R I_b R^T) omega + 1/2 m |tdot|^2 with the world
angular velocity omega = T(r) rdot (see docs/derivation.md, "Angular velocity").
"""
import time

import numpy as np

from diff_rigid_body_examples.pose_fitting import rpy_to_matrix

__all__ = ['demo_trajectory', 'kinetic_energy', 'energy_batched', 'energy_per_call', 'energy_from_inertia']


def demo_trajectory(q0, count, duration=2.0, seed=0):
    """A smooth trajectory of n bodies around q0 (n, 6): per coordinate
    q(t) = q0 + a sin(w t + c), with its exact qdot.

    Returns t (K,) [s], q (K, n, 6) and qdot (K, n, 6) [rad/s, m/s].
    """
    q0 = np.asarray(q0, dtype=float)
    rng = np.random.default_rng(seed)
    amplitude = np.where(np.arange(6) < 3, 0.6, 0.1) * rng.uniform(0.5, 1.0, size=q0.shape)
    omega = 2.0 * np.pi * rng.uniform(0.3, 1.2, size=q0.shape)
    phase = rng.uniform(0.0, 2.0 * np.pi, size=q0.shape)
    t = np.linspace(0.0, duration, count)
    angle = omega * t[:, None, None] + phase
    return t, q0 + amplitude * np.sin(angle), amplitude * omega * np.cos(angle)


def kinetic_energy(M, qdot):
    """1/2 qdot^T M qdot over the last two axes: M (..., 6, 6), qdot (..., 6)."""
    return 0.5 * np.einsum('...i,...ij,...j->...', qdot, M, qdot)


def energy_batched(client, bodies, q, qdot, repeat=1):
    """E (K, n) [J] from one ``get_mass_matrix`` call; and its wall time [s]
    (the best of ``repeat`` calls)."""
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        E = kinetic_energy(client.mass_matrix(bodies, q=q).M, qdot)
        best = min(best, time.perf_counter() - start)
    return E, best


def energy_per_call(client, bodies, q, qdot):
    """E (K, n) [J] from K ``get_mass_matrix`` calls, one configuration each;
    and the wall time [s]."""
    start = time.perf_counter()
    E = np.array([kinetic_energy(client.mass_matrix(bodies, q=q_k).M, qdot_k) for q_k, qdot_k in zip(q, qdot)])
    return E, time.perf_counter() - start


def energy_from_inertia(masses, inertias, q, qdot):
    """E (K, n) [J] from masses (n,) [kg] and body-axis inertias (n, 3, 3)
    [kg m^2] about the COM, without M: 1/2 w^T R I_b R^T w + 1/2 m |v|^2."""
    K, n = q.shape[:2]
    E = np.empty((K, n))
    for k in range(K):
        for i in range(n):
            phi, theta, psi = q[k, i, :3]
            T = np.array([[np.cos(theta) * np.cos(psi), -np.sin(psi), 0.0],
                          [np.cos(theta) * np.sin(psi), np.cos(psi), 0.0],
                          [-np.sin(theta), 0.0, 1.0]])
            R = rpy_to_matrix(q[k, i, :3])
            w = T.dot(qdot[k, i, :3])
            v = qdot[k, i, 3:]
            E[k, i] = 0.5 * w.dot(R.dot(inertias[i]).dot(R.T)).dot(w) + 0.5 * masses[i] * v.dot(v)
    return E
