#!/usr/bin/python3
"""The README's example client: two optimisers and a batched trajectory,
against a running rigid_body_server (the default scene).

1. Pose fitting: target vertex positions of one body at a hidden pose (with
   and without noise); recover q from a start 30 deg and 0.2 m away by
   Gauss-Newton (get_vertex_jacobians), by L-BFGS (backprop) and by SciPy's
   least_squares (get_vertex_jacobians as jac).
2. Kinetic energy E = 1/2 qdot^T M(q) qdot along a K-configuration
   trajectory: one batched get_mass_matrix call against K calls.

Usage: demo_client.py [--body knot] [--noise 0.001] [--configurations 1000]

Exits 1 unless every fit converged: without noise each fit must recover the
hidden pose to EXACT_ANGLE [rad] and EXACT_POSITION [m]; with noise the two
fits must agree with each other to AGREE_ANGLE [rad] and AGREE_POSITION [m].
On success the last line is "demo: all fits converged".
"""
import argparse
import sys

import numpy as np
import rospy

from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient
from diff_rigid_body import pose_fitting, trajectory_energy, trajectory_fitting

Q_HIDDEN = np.array([0.3, -0.4, 1.1, 0.05, -0.1, 0.6])  # the pose to recover
EXACT_ANGLE, EXACT_POSITION = 1e-8, 1e-8  # [rad], [m]: noise-free fit vs Q_HIDDEN
AGREE_ANGLE, AGREE_POSITION = 1e-6, 1e-6  # [rad], [m]: noisy fits, one vs the other
# Trajectory: q0 (rad, m) and qdot0 (rad/s, m/s) of the toss to recover.
X_HIDDEN = np.array([0.2, -0.3, 0.5, 0.0, 0.0, 1.0, 1.5, 0.8, -1.0, 0.5, -0.3, 4.0])
AGREE_TRAJECTORY = 1e-6   # max |x_torch - x_least_squares|
NOISE_SIGMAS = 5.0        # max |x_fit - x_hidden| / standard deviation of the estimate


def print_scene(client):
    bodies = client.bodies()
    print("Scene (fixed frame '%s'):" % bodies.fixed_frame)
    for i, name in enumerate(bodies.names):
        diagonal = ', '.join('%.3e' % v for v in np.diag(bodies.inertias[i]))
        print('  %-6s %8.5f kg  %5d vertices  I_b diagonal (%s) kg m^2' % (
            name, bodies.masses[i], bodies.vertex_counts[i], diagonal))
    return bodies


def pose_fitting_example(client, body, noises):
    """Prints one row per fit; returns the list of failures (empty: all converged)."""
    print('\n1. Pose fitting of %r: hidden q = %s' % (body, np.array2string(Q_HIDDEN, precision=3)))
    print('   %-26s %7s %6s %6s %12s %13s %13s %9s' % (
        'solver', 'noise', 'iters', 'calls', 'rms resid', 'angle error', 'pos error', 'time'))
    failures = []
    for noise in noises:
        target, q_start = pose_fitting.make_problem(client, body, Q_HIDDEN, noise=noise, seed=3)
        angle, distance = pose_fitting.pose_error(q_start, Q_HIDDEN)
        print('   start: %.1f deg and %.3f m away (noise %g m)' % (np.degrees(angle), distance, noise))
        fitted = []
        for label, fit in (('Gauss-Newton (jacobians)', pose_fitting.fit_gauss_newton),
                           ('L-BFGS (backprop)', pose_fitting.fit_lbfgs),
                           ('least_squares (jacobians)', pose_fitting.fit_least_squares)):
            result = fit(client, body, target, q_start)
            angle, distance = pose_fitting.pose_error(result.q, Q_HIDDEN)
            print('   %-26s %7g %6d %6d %10.3e m %9.3e rad %11.3e m %7.3f s%s' % (
                label, noise, result.iterations, result.evaluations, result.residual_rms, angle, distance,
                result.wall_time, '' if result.converged else '  (NOT CONVERGED: %s)' % result.reason))
            if not result.converged:
                failures.append('%s, noise %g m: not converged (%s)' % (label, noise, result.reason))
            elif noise == 0.0 and not (angle < EXACT_ANGLE and distance < EXACT_POSITION):
                failures.append('%s, no noise: %.3e rad and %.3e m from the hidden pose (tolerance %g rad, %g m)'
                                % (label, angle, distance, EXACT_ANGLE, EXACT_POSITION))
            fitted.append(result.q)
        if noise != 0.0:
            errors = [pose_fitting.pose_error(q, fitted[0]) for q in fitted[1:]]
            angle, distance = max(e[0] for e in errors), max(e[1] for e in errors)
            print('   the fits differ from Gauss-Newton by at most %.3e rad and %.3e m' % (angle, distance))
            if not (angle < AGREE_ANGLE and distance < AGREE_POSITION):
                failures.append('noise %g m: the fits differ by %.3e rad and %.3e m (tolerance %g rad, %g m)'
                                % (noise, angle, distance, AGREE_ANGLE, AGREE_POSITION))
    return failures


def trajectory_example(client, bodies, count):
    q0 = np.array([client.get_state()[name] for name in bodies.names])
    t, q, qdot = trajectory_energy.demo_trajectory(q0, count)
    print('\n2. Kinetic energy along a trajectory: K = %d configurations of %d bodies (%s), %.1f s' % (
        count, len(bodies.names), ', '.join(bodies.names), t[-1]))
    batched, batched_time = trajectory_energy.energy_batched(client, bodies.names, q, qdot, repeat=3)
    per_call, per_call_time = trajectory_energy.energy_per_call(client, bodies.names, q, qdot)
    oracle = trajectory_energy.energy_from_inertia(bodies.masses, bodies.inertias, q, qdot)
    for i, name in enumerate(bodies.names):
        print('   %-6s E in [%.4e, %.4e] J, mean %.4e J' % (name, batched[:, i].min(), batched[:, i].max(),
                                                             batched[:, i].mean()))
    print('   one batched call: %8.4f s   (best of 3; M comes back as K x n x 6 x 6)' % batched_time)
    print('   %d single calls: %8.4f s   speed-up %.0fx' % (count, per_call_time, per_call_time / batched_time))
    print('   max relative difference, batched vs single calls:      %.2e' % np.max(
        np.abs(batched - per_call) / np.abs(per_call)))
    print('   max relative difference vs 1/2 w^T I w + 1/2 m |v|^2:   %.2e' % np.max(
        np.abs(batched - oracle) / np.abs(oracle)))


def trajectory_fitting_example(client, body, noise, frames):
    """Fits a toss; prints one row per solver; returns the list of failures."""
    times = np.arange(frames) / 100.0  # 100 frames per second
    bodies = client.bodies()
    vertices = np.linspace(0, bodies.vertex_counts[bodies.names.index(body)] - 1, 64).astype(np.uint32)
    observed, x_start = trajectory_fitting.make_problem(client, body, X_HIDDEN, times, vertices, noise, seed=5)
    sigma = trajectory_fitting.standard_errors(client, body, X_HIDDEN, times, vertices, noise)
    print('\n3. Trajectory fitting of a tossed %r: q0, qdot0 from T = %d frames (%.2f s) of %d vertices, '
          'noise %g m' % (body, frames, times[-1], len(vertices), noise))
    print('   start off by %.2e rad, %.2e m, %.2e rad/s, %.2e m/s; standard deviations of the estimate up to '
          '%.1e rad, %.1e m, %.1e rad/s, %.1e m/s' % (trajectory_fitting.errors(x_start, X_HIDDEN) + tuple(
              sigma.reshape(4, 3).max(axis=1))))
    print('   %-22s %6s %6s %6s %10s %11s %12s %10s %12s %12s %9s' % (
        'solver', 'iters', 'evals', 'calls', 'per-frame', 'rms resid', 'angles', 'position', 'ang. rates',
        'velocity', 'time'))
    failures, fitted = [], []
    for label, fit in (('torch LBFGS (backprop)', trajectory_fitting.fit_torch),
                       ('least_squares (J)', trajectory_fitting.fit_least_squares)):
        r = fit(client, body, observed, times, x_start, vertices)
        e = trajectory_fitting.errors(r.x, X_HIDDEN)
        print('   %-22s %6d %6d %6d %10d %8.3e m %6.2e rad %6.2e m %6.2e r/s %6.2e m/s %7.3f s%s' % (
            (label, r.iterations, r.evaluations, r.calls, r.per_frame_calls, r.residual_rms) + e + (
                r.wall_time, '' if r.converged else '  (NOT CONVERGED: %s)' % r.reason)))
        sigmas = np.max(np.abs(r.x - X_HIDDEN) / sigma)
        if not r.converged:
            failures.append('trajectory, %s: not converged (%s)' % (label, r.reason))
        elif sigmas > NOISE_SIGMAS:
            failures.append('trajectory, %s: %.1f standard deviations from the hidden truth (at most %g)'
                            % (label, sigmas, NOISE_SIGMAS))
        fitted.append(r)
    print('   round trips saved by batched calls: %d of %d' % tuple(
        (sum(r.per_frame_calls - r.calls for r in fitted), sum(r.per_frame_calls for r in fitted))))
    difference = np.max(np.abs(fitted[0].x - fitted[1].x))
    print('   the two fits differ by %.2e (max over q0, qdot0); errors vs truth at most %.1f standard deviations'
          % (difference, max(np.max(np.abs(r.x - X_HIDDEN) / sigma) for r in fitted)))
    if difference > AGREE_TRAJECTORY:
        failures.append('trajectory: the two fits differ by %.2e (at most %g)' % (difference, AGREE_TRAJECTORY))
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--server', default='rigid_body_server')
    parser.add_argument('--body', default='knot', help='body to fit (default: knot)')
    parser.add_argument('--noise', type=float, default=1e-3, help='[m] noise of the noisy fit (default: 1 mm)')
    parser.add_argument('--configurations', type=int, default=1000, help='K (default: 1000)')
    parser.add_argument('--frames', type=int, default=120, help='T of the trajectory fit (default: 120)')
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node('demo_client', anonymous=True)

    client = RigidBodyClient(args.server).connect()  # persistent connections, opened before any timing
    bodies = print_scene(client)
    failures = pose_fitting_example(client, args.body, [0.0, args.noise])
    trajectory_example(client, bodies, args.configurations)
    failures += trajectory_fitting_example(client, 'knot', args.noise, args.frames)
    try:
        client.vertex_jacobians('no_such_body')
    except DiffRigidBodyError as e:
        print('\nA refused request raises DiffRigidBodyError: %s' % e)
    for failure in failures:
        print('demo: FAILED: %s' % failure)
    if failures:
        return 1
    print('demo: all fits converged')
    return 0


if __name__ == '__main__':
    sys.exit(main())
