"""Oracles for the dynamics rostests (dynamics_check.py), written from the
definitions of docs/interface.md "Version 3" without the node's dynamics code:

- the Christoffel Coriolis matrix from dM/dx (get_mass_matrix's derivatives);
- the potential V(x) = - sum over links of m_l gamma^T c_l(x), its COMs c_l from
  this test's own forward kinematics of the URDF XML (robot_joints_check.py)
  and get_bodies' link masses and COM offsets, or for a free body from its
  q = (phi, theta, psi, t), t being its COM;
- central differences of a function evaluated at K = 2d configurations in one call.
"""
import numpy as np

from robot_joints_check import forward_kinematics, read_joints

STANDARD_GRAVITY = np.array([0.0, 0.0, -9.81])  # [m/s^2], ~gravity's documented default


def christoffel_coriolis(dM, xdot):
    """C (d, d) with C_ij = sum_k 1/2 (dM_ij/dx_k + dM_ik/dx_j - dM_jk/dx_i) xdot_k, from dM
    (d, d, d) with dM[k] = dM/dx_k."""
    G = 0.5 * (np.einsum('kij->ijk', dM) + np.einsum('jik->ijk', dM) - np.einsum('ijk->ijk', dM))
    return np.einsum('ijk,k->ij', G, xdot)


def mass_matrix_rate(dM, xdot):
    """dM/dt = sum_k dM/dx_k xdot_k, (d, d)."""
    return np.einsum('kij,k->ij', dM, xdot)


def steps(x, h):
    """The 2d configurations x + h e_j (rows 0..d-1) and x - h e_j (rows d..2d-1) of x (..., d),
    varying coordinate j of every body at once: shape (2d,) + x.shape."""
    d = x.shape[-1]
    unit = np.eye(d).reshape((d,) + (1,) * (x.ndim - 1) + (d,))
    return np.concatenate([x + h * unit, x - h * unit])


def central_differences(values, h):
    """d(value)/dx_j from ``values`` (2d, ..., m) at steps(x, h): (..., m, d), rows = value components."""
    d = values.shape[0] // 2
    return np.moveaxis((values[:d] - values[d:]) / (2 * h), 0, -1)


class ArticulatedPotential(object):
    """V(x) [J] of one articulated body: its link COMs from the URDF's forward kinematics."""

    def __init__(self, urdf, joint_names, links, gamma=STANDARD_GRAVITY):
        self.joints = read_joints(urdf)
        self.joint_names = list(joint_names)
        self.links = [(link.name, link.mass, np.asarray(link.com_offset)) for link in links]
        self.gamma = np.asarray(gamma)

    def __call__(self, x):
        poses = forward_kinematics(self.joints, dict(zip(self.joint_names, x)))
        V = 0.0
        for name, mass, com_offset in self.links:
            com = poses[name][:3, :3] @ com_offset + poses[name][:3, 3]
            V -= mass * self.gamma @ com
        return V


class FreePotential(object):
    """V(q) [J] of a free body of mass m: - m gamma^T t, t = q[3:6] its COM."""

    def __init__(self, mass, gamma=STANDARD_GRAVITY):
        self.mass, self.gamma = float(mass), np.asarray(gamma)

    def __call__(self, q):
        return -self.mass * self.gamma @ np.asarray(q)[3:6]
