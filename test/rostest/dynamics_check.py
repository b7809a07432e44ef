#!/usr/bin/python3
"""~inverse_dynamics and ~forward_dynamics (docs/interface.md "Version 3") through the Python client,
on the Franka Panda (one fixed-base body, d = 8, ~joints: model) and on the default scene (two
free bodies, d = 6), each checked against identities and oracles that do not use the node's
dynamics code (dynamics.test):

- tau = M x'' + c + g, M from get_mass_matrix; g = tau(x, 0, 0), c = tau(x, x', 0) - g;
- C equals the Christoffel matrix of get_mass_matrix's dM/dx; c = C x'; dM/dt - 2C is
  skew-symmetric; dtau/dx' = 2C;
- g = dV/dx by central differences of V = - sum_l m_l gamma^T c_l(x) (dynamics_oracles.py: the
  link COMs from this test's own forward kinematics of the URDF, or a free body's t);
- dtau/dx, dx''/dx and dx''/dx' against central differences of the served tau and x'';
  dx''/dx = -M^-1 dtau/dx;
- FD(ID(x'')) = x''; dx''/dtau M = I;
- K = 3 configurations in one call equal three single calls bit for bit;
- refusals (wrong lengths, NaN, an unknown body, forward dynamics at gimbal lock naming the
  body and configuration) change nothing, and inverse dynamics stays finite at gimbal lock;
- with ~gravity [0, 0, 0] (a second Panda node) g = 0 and tau is the default node's tau - g.

Tolerances, relative to the largest entry compared: products and sums of the same doubles,
1e-12 (rounding of ~d terms of eps = 2.2e-16; measured <= 1e-15); through M^-1 (FD(ID(x'')),
dx''/dtau M), 1e-10 (cond(M) eps, the Panda's cond(M) ~ 1e4; measured <= 1.6e-14). C, c and the
matrices of test_b are compared in the metric of M, D^-1/2 (.) D^-1/2 (vectors D^-1/2 (.)),
D = diag(M), so that coordinates in rad and m weigh alike, within 1e-11: a free body's
translational rows of C are 0 in theory and ~1e-16 as served, rounding next to m = 1.45 kg but
not next to the knot's rotational entries ~1e-4 kg m^2/s (measured <= 2.2e-13, the knot's c).
Central differences (h = 1e-6) against a served Jacobian J of f: |error| <= 1e-6 max |J|
+ 16 eps max |f| / h, the second term their rounding (a free body's tau holds m g ~ 14 N;
measured <= 0.024 of this bound).
"""
import sys
import unittest

import numpy as np
import rospy
import rostest

from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient
from dynamics_oracles import (ArticulatedPotential, FreePotential, central_differences, christoffel_coriolis,
                              mass_matrix_rate, steps)

PKG = 'diff_rigid_body'
TIMEOUT = 100.0      # [s] for the nodes to load their meshes and advertise
EXACT = 1e-12        # relative, the same numbers combined differently
INVERSE = 1e-10      # relative, through M^-1
METRIC = 1e-11       # relative, in the metric of M (in_metric)
FD_STEP = 1e-6       # [rad or m]
FD_TOLERANCE = 1e-6  # relative to max |J|
FD_ROUNDING = 16 * np.finfo(float).eps  # times max |f| / h


def relative_error(got, expected):
    scale = max(np.abs(expected).max(), np.abs(got).max(), 1e-300)
    return np.abs(np.asarray(got) - np.asarray(expected)).max() / scale


def in_metric(values, M):
    """A vector (d,) as D^-1/2 v or a matrix (d, d) as D^-1/2 A D^-1/2, D = diag(M)."""
    scale = 1.0 / np.sqrt(np.diag(M))
    return scale * values if np.ndim(values) == 1 else scale[:, None] * values * scale[None, :]


def finite_difference_error(served, values, h):
    """|served J - central differences of ``values`` (at the steps(x, h) rows)| over its bound
    FD_TOLERANCE max |J| + FD_ROUNDING max |f| / h: at most 1 passes."""
    error = np.abs(served - central_differences(values, h)).max()
    return error / (FD_TOLERANCE * np.abs(served).max() + FD_ROUNDING * np.abs(values).max() / h)


class Scene(object):
    """A node under test: its bodies (all of one d), a configuration x, rates and accelerations,
    each (n, d), and each body's potential V(x_i)."""

    def __init__(self, name, server, x_for_body, potential_for_body, seed):
        self.name = name
        self.client = RigidBodyClient(server, timeout=TIMEOUT)
        bodies = self.client.bodies()
        self.bodies, self.d = list(bodies.names), int(bodies.dofs[0])
        rng = np.random.default_rng(seed)
        self.x = np.array([x_for_body(bodies, i) for i in range(len(self.bodies))])
        self.xdot = rng.uniform(-1.0, 1.0, self.x.shape)
        self.xddot = rng.uniform(-2.0, 2.0, self.x.shape)
        self.potentials = [potential_for_body(bodies, i) for i in range(len(self.bodies))]

    def inverse(self, *args, **kwargs):
        return self.client.inverse_dynamics(self.bodies, *args, **kwargs)

    def forward(self, *args, **kwargs):
        return self.client.forward_dynamics(self.bodies, *args, **kwargs)

    def mass_matrices(self, q, derivatives=False):
        return self.client.mass_matrix(self.bodies, q, derivatives)


def panda_x(bodies, i):
    """30% .. 65% of the way from each joint's lower to its upper limit."""
    return np.array([j.lower + (0.3 + 0.05 * k) * (j.upper - j.lower) for k, j in enumerate(bodies.joints[i])])


def free_x(bodies, i):
    """Away from gimbal lock (|theta| <= 0.6) and from the identity."""
    return np.array([[0.3, -0.6, 1.1, 0.2, -0.1, 0.6], [-0.7, 0.45, -2.0, -0.3, 0.25, 0.4]])[i % 2]


class Dynamics(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        urdf = rospy.get_param('~urdf')
        panda = Scene('panda', rospy.get_param('~panda_server', '/rigid_body_server'), panda_x,
                      lambda b, i: ArticulatedPotential(urdf, [j.name for j in b.joints[i]], b.links[i]), 3)
        free = Scene('scene', rospy.get_param('~scene_server', '/scene/rigid_body_server'), free_x,
                     lambda b, i: FreePotential(b.masses[i]), 4)
        cls.scenes = [panda, free]
        cls.zero_gravity = RigidBodyClient(rospy.get_param('~zero_gravity_server', '/zero_gravity/rigid_body_server'),
                                           timeout=TIMEOUT)

    def report(self, scene, what, error, tolerance):
        sys.stdout.write('%s: %s: %.3g (tolerance %g)\n' % (scene.name, what, error, tolerance))
        self.assertLessEqual(error, tolerance, '%s: %s differs by %.3g (relative)' % (scene.name, what, error))

    def test_a_tau_is_M_qddot_plus_c_plus_g(self):
        for s in self.scenes:
            answer = s.inverse(s.x, s.xdot, s.xddot)
            self.assertEqual(np.shape(answer.tau), (len(s.bodies), s.d), '%s: tau shape' % s.name)
            M = s.mass_matrices(s.x).M
            expected = np.einsum('nab,nb->na', M, s.xddot) + answer.c + answer.g
            self.report(s, 'tau vs M qddot + c + g', relative_error(answer.tau, expected), EXACT)
            g = s.inverse(s.x).tau
            c = s.inverse(s.x, s.xdot).tau - g
            self.report(s, 'g vs tau(x, 0, 0)', relative_error(answer.g, g), EXACT)
            self.report(s, 'c vs tau(x, xdot, 0) - g', relative_error(answer.c, c), EXACT)

    def test_b_coriolis_matrix_is_christoffel(self):
        for s in self.scenes:
            answer = s.inverse(s.x, s.xdot, s.xddot, coriolis_matrices=True, derivatives=True)
            mass = s.mass_matrices(s.x, derivatives=True)
            for i, body in enumerate(s.bodies):
                M, dM, C, xdot = mass.M[i], mass.dM[i], answer.C[i], s.xdot[i]

                def compare(what, got, expected):
                    self.report(s, '%s: %s (metric of M)' % (body, what),
                                relative_error(in_metric(got, M), in_metric(expected, M)), METRIC)
                compare('C vs Christoffel of dM/dx', C, christoffel_coriolis(dM, xdot))
                compare('c vs C xdot', answer.c[i], C @ xdot)
                N = in_metric(mass_matrix_rate(dM, xdot) - 2 * C, M)
                self.report(s, '%s: dM/dt - 2C skew-symmetric (metric of M)' % body,
                            np.abs(N + N.T).max() / np.abs(N).max(), METRIC)
                compare('dtau/dqdot vs 2C', answer.dtau_dqdot[i], 2 * C)

    def test_c_gravity_is_the_gradient_of_the_potential(self):
        for s in self.scenes:
            g = s.inverse(s.x).g
            for i, body in enumerate(s.bodies):
                V = np.array([[s.potentials[i](x)] for x in steps(s.x[i], FD_STEP)])
                self.report(s, '%s: g vs dV/dx (own kinematics), over the bound' % body,
                            finite_difference_error(g[i][None, :], V, FD_STEP), 1.0)

    def test_d_inverse_dynamics_derivatives(self):
        for s in self.scenes:
            answer = s.inverse(s.x, s.xdot, s.xddot, derivatives=True)
            K = 2 * s.d
            moved_q = s.inverse(steps(s.x, FD_STEP), np.stack([s.xdot] * K), np.stack([s.xddot] * K)).tau
            moved_qdot = s.inverse(np.stack([s.x] * K), steps(s.xdot, FD_STEP), np.stack([s.xddot] * K)).tau
            self.report(s, 'dtau/dq vs central differences, over the bound',
                        finite_difference_error(answer.dtau_dq, moved_q, FD_STEP), 1.0)
            self.report(s, 'dtau/dqdot vs central differences, over the bound',
                        finite_difference_error(answer.dtau_dqdot, moved_qdot, FD_STEP), 1.0)

    def test_e_forward_dynamics_inverts_inverse_dynamics(self):
        for s in self.scenes:
            inverse = s.inverse(s.x, s.xdot, s.xddot, derivatives=True)
            forward = s.forward(s.x, s.xdot, inverse.tau, derivatives=True)
            self.report(s, 'FD(ID(qddot)) vs qddot', relative_error(forward.qddot, s.xddot), INVERSE)
            M = s.mass_matrices(s.x).M
            identity = np.broadcast_to(np.eye(s.d), M.shape)
            self.report(s, 'dqddot/dtau M vs I', relative_error(forward.dqddot_dtau @ M, identity), INVERSE)
            self.report(s, 'dqddot/dq vs -M^-1 dtau/dq',
                        relative_error(forward.dqddot_dq, -np.linalg.solve(M, inverse.dtau_dq)), INVERSE)

    def test_f_forward_dynamics_derivatives(self):
        for s in self.scenes:
            tau = s.inverse(s.x, s.xdot, s.xddot).tau
            answer = s.forward(s.x, s.xdot, tau, derivatives=True)
            K = 2 * s.d
            moved_q = s.forward(steps(s.x, FD_STEP), np.stack([s.xdot] * K), np.stack([tau] * K)).qddot
            moved_qdot = s.forward(np.stack([s.x] * K), steps(s.xdot, FD_STEP), np.stack([tau] * K)).qddot
            moved_tau = s.forward(np.stack([s.x] * K), np.stack([s.xdot] * K), steps(tau, FD_STEP)).qddot
            for name, served, moved in (('dqddot/dq', answer.dqddot_dq, moved_q),
                                        ('dqddot/dqdot', answer.dqddot_dqdot, moved_qdot),
                                        ('dqddot/dtau', answer.dqddot_dtau, moved_tau)):
                self.report(s, '%s vs central differences, over the bound' % name,
                            finite_difference_error(served, moved, FD_STEP), 1.0)

    def test_g_batched_equals_single_calls(self):
        for s in self.scenes:
            rng = np.random.default_rng(11)
            q = np.stack([s.x, s.x + 0.1, s.x - 0.05])  # (3, n, d)
            qdot, qddot = rng.uniform(-1, 1, q.shape), rng.uniform(-1, 1, q.shape)
            inverse = s.inverse(q, qdot, qddot, coriolis_matrices=True, derivatives=True)
            forward = s.forward(q, qdot, inverse.tau, derivatives=True)
            for k in range(3):
                one_inverse = s.inverse(q[k], qdot[k], qddot[k], coriolis_matrices=True, derivatives=True)
                one_forward = s.forward(q[k], qdot[k], inverse.tau[k], derivatives=True)
                for field in ('tau', 'c', 'g', 'C', 'dtau_dq', 'dtau_dqdot', 'cos_theta'):
                    self.assertTrue(np.array_equal(getattr(inverse, field)[k], getattr(one_inverse, field)),
                                    '%s: inverse_dynamics %s of configuration %d: batched differs' % (s.name, field, k))
                for field in ('qddot', 'dqddot_dq', 'dqddot_dqdot', 'dqddot_dtau', 'cos_theta'):
                    self.assertTrue(np.array_equal(getattr(forward, field)[k], getattr(one_forward, field)),
                                    '%s: forward_dynamics %s of configuration %d: batched differs' % (s.name, field, k))

    def assertRefused(self, call, fragments, what):
        with self.assertRaises(DiffRigidBodyError, msg='%s was not refused' % what) as refusal:
            call()
        for fragment in fragments:
            self.assertIn(fragment, refusal.exception.message, '%s: the message does not say %r' % (what, fragment))

    def test_h_refusals(self):
        for s in self.scenes:
            before = s.client.get_state()
            D = len(s.bodies) * s.d
            x, nan = s.x.ravel(), np.zeros(D)
            nan[2] = np.nan
            for service in (s.client.inverse_dynamics, s.client.forward_dynamics):
                what = '%s, %s: ' % (s.name, service.__name__)
                self.assertRefused(lambda: service(np.append(x, 0.0), bodies=s.bodies), ['q'], what + 'D + 1 q')
                self.assertRefused(lambda: service(x, np.zeros(D - 1), bodies=s.bodies), ['qdot'], what + 'D - 1 qdot')
                self.assertRefused(lambda: service(x, nan, bodies=s.bodies), ['qdot', 'finite'], what + 'a NaN')
                self.assertRefused(lambda: service(bodies=['nope']), ["unknown body 'nope'"], what + 'unknown body')
            self.assertRefused(lambda: s.inverse(x, qddot=np.zeros(D + 1)), ['qddot'], '%s: D + 1 qddot' % s.name)
            self.assertRefused(lambda: s.forward(x, tau=np.zeros(D + 1)), ['tau'], '%s: D + 1 tau' % s.name)
            after = s.client.get_state()
            for name in before:
                self.assertTrue(np.array_equal(before[name], after[name]), '%s: a refusal changed %s' % (s.name, name))

    def test_i_gimbal_lock(self):
        s = self.scenes[1]  # free bodies
        locked = s.x.copy()
        locked[1, 1] = np.pi / 2  # the second body's theta
        body = s.bodies[1]
        self.assertRefused(lambda: s.forward(locked), ["'%s'" % body, 'singular'], 'forward dynamics at gimbal lock')
        self.assertRefused(lambda: s.forward(np.stack([s.x, locked])), ["'%s'" % body, 'configuration 1'],
                           'forward dynamics with configuration 1 at gimbal lock')
        answer = s.inverse(locked, s.xdot, s.xddot, coriolis_matrices=True, derivatives=True)
        for field in ('tau', 'c', 'g', 'C', 'dtau_dq', 'dtau_dqdot'):
            self.assertTrue(np.all(np.isfinite(getattr(answer, field))), 'inverse dynamics at gimbal lock: %s' % field)
        self.assertLess(abs(answer.cos_theta[1]), 1e-15, 'cos(theta) at gimbal lock')

    def test_j_zero_gravity(self):
        s = self.scenes[0]  # the Panda, served again with ~gravity [0, 0, 0]
        body = self.zero_gravity.bodies().names
        self.assertEqual(body, s.bodies, 'the zero-gravity node serves another robot')
        zero = self.zero_gravity.inverse_dynamics(body, s.x, s.xdot, s.xddot)
        self.assertTrue(np.all(zero.g == 0.0), 'g with ~gravity [0, 0, 0]: %s' % zero.g)
        default = s.inverse(s.x, s.xdot, s.xddot)
        self.report(s, 'tau without gravity vs tau - g', relative_error(zero.tau, default.tau - default.g), EXACT)
        self.assertGreater(np.abs(default.g).max(), 1.0, 'the default node has gravity')
        rest = self.zero_gravity.forward_dynamics(body, s.x).qddot
        self.assertTrue(np.all(rest == 0.0), 'at rest without gravity or forces x\'\' = 0, got %s' % rest)


if __name__ == '__main__':
    rospy.init_node('dynamics_check')
    rostest.rosrun(PKG, 'dynamics_check', Dynamics)
