#!/usr/bin/python3
"""Example optimiser for an articulated body: recovers an arm's joint
positions from observed vertex positions (inverse kinematics from points,
as in camera-to-robot calibration), against a running rigid_body_server
that serves a robot with ~joints: model (e.g. the Panda).

A hidden configuration x* within the joint limits is drawn; the vertices
of the arm's last links at x* (plus noise) are the observations; the fit
starts from x = 0 clipped into the limits (or, with --start state, from the
node's current state, e.g. what joint_states set) and uses SciPy's least_squares with the node's
dp/dx as the Jacobian and the joint limits as bounds. The result is set as
the node's state, so tf and rviz show the fitted arm.

Usage: joint_fit_client.py [--server /arm/rigid_body_server] [--noise 0.0] [--start zero|state]

Exits 1 unless the fit converges: without noise to EXACT [rad or m] of x*;
with noise to NOISE_SIGMAS standard deviations of the estimate. On success
the last line is "joint fit: converged".
"""
import argparse
import sys

import numpy as np
import rospy

from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient
from diff_rigid_body_examples.joint_fitting import fit_joints, joint_bounds

EXACT = 1e-8          # [rad or m] noise-free fit vs x*
NOISE_SIGMAS = 5.0    # noisy fit: max |x - x*| / standard deviation of the estimate
SEED = 12


def articulated_body(client):
    """The first body with joints, and its dof."""
    bodies = client.bodies()
    for name, dofs, joints in zip(bodies.names, bodies.dofs, bodies.joints):
        if joints:
            return name, int(dofs)
    raise SystemExit('joint fit: the scene has no body with joints (start the node with ~joints: model on a robot)')


def hidden_configuration(lower, upper, rng):
    """A configuration well inside the limits (continuous joints: within +-1 rad)."""
    low, high = np.maximum(lower, -1.0), np.minimum(upper, 1.0)
    return low + (0.25 + 0.5 * rng.random(len(lower))) * (high - low)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--server', default='rigid_body_server')
    parser.add_argument('--noise', type=float, default=0.0, help='[m] standard deviation of the observations')
    parser.add_argument('--start', choices=('zero', 'state'), default='zero',
                        help='start from x = 0 (clipped into the limits) or from the node\'s current state')
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node('joint_fit_client', anonymous=True, disable_signals=True)
    rng = np.random.default_rng(SEED)
    with RigidBodyClient(args.server) as client:
        body, dofs = articulated_body(client)
        lower, upper = joint_bounds(client, body)
        x_hidden = hidden_configuration(lower, upper, rng)
        observed = client.positions(body, q=x_hidden)
        observed = observed + args.noise * rng.standard_normal(observed.shape)
        x0 = client.get_state([body])[body] if args.start == 'state' else np.zeros(dofs)
        x, result, calls = fit_joints(client, body, observed, x0)
        error = np.abs(x - x_hidden).max()
        print('joint fit of %s (%d coordinates, %d vertices): %d round trips, |x - x*|_inf = %.3g, cost %.3g'
              % (body, dofs, len(observed), calls, error, result.cost))
        if args.noise > 0.0:
            J = client.vertex_jacobians(body, q=x)[1].reshape(-1, dofs)
            sigma = args.noise * np.sqrt(np.diag(np.linalg.pinv(J.T @ J)))
            ok = result.success and np.all(np.abs(x - x_hidden) <= NOISE_SIGMAS * sigma)
        else:
            ok = result.success and error <= EXACT
        client.set_state({body: x})
    if not ok:
        print('joint fit: did not converge (%s)' % result.message)
        return 1
    print('joint fit: converged')
    return 0


if __name__ == '__main__':
    try:
        sys.exit(main())
    except DiffRigidBodyError as error:
        print('joint fit: the node refused a request: %s' % error)
        sys.exit(1)
