#!/usr/bin/python3
"""The README's example client: optimisers, a batched trajectory and a
tossed T-handle, against a running rigid_body_server (the default scene) and
a second one serving urdf/t_handle.urdf (namespace t_handle).

1. Pose fitting: target vertex positions of one body at a hidden pose (with
   and without noise); recover q from a start 30 deg and 0.2 m away by
   Gauss-Newton (get_vertex_jacobians), by L-BFGS (backprop) and by SciPy's
   least_squares (get_vertex_jacobians as jac).
2. Kinetic energy E = 1/2 qdot^T M(q) qdot along a K-configuration
   trajectory: one batched get_mass_matrix call against K calls.
3. A tossed T-handle spun about its intermediate axis (it flips: the
   Dzhanibekov effect), integrated by RK4 through forward_dynamics with the
   node's gravity (diff_rigid_body_examples.dynamics_fitting). Its sensitivities
   ds/ds0 (the variational equations, from the served dqddot_dq and
   dqddot_dqdot) are checked against central differences; (q0, q0') (12
   numbers) are recovered from noisy positions of 32 of its vertices at T
   frames by torch LBFGS and by SciPy's least_squares, with those exact
   gradients; the flip time is reported with its standard deviation.

Usage: demo_client.py [--body knot] [--noise 0.001] [--configurations 1000] [--frames 60]
                      [--t-handle-server /t_handle/rigid_body_server] [--backend node|local]
                      [--drop-dqddot-dq]

--backend local runs example 3 (the T-handle's dynamics and trajectory fits)
in this process on diff_rigid_body.LocalScene, loaded from urdf/t_handle.urdf
with the node's defaults, instead of through the t_handle node: the same
client calls, the node's numbers bit for bit.

Exits 1 unless every fit converged: without noise each pose fit must recover
the hidden pose to EXACT_ANGLE [rad] and EXACT_POSITION [m]; with noise the
pose fits must agree with each other to AGREE_ANGLE [rad] and AGREE_POSITION
[m]; both T-handle fits must converge, agree to AGREE_TRAJECTORY and lie
within NOISE_SIGMAS standard deviations of the hidden toss (q0, q0' and the
flip time), and the sensitivities must match central differences to
SENSITIVITY_TOLERANCE. --drop-dqddot-dq leaves dx''/dx out of the
sensitivities: a deliberately wrong gradient, which these checks catch (the
demo then exits 1). On success the last line is "demo: all fits converged".
"""
import argparse
import sys
import time

import numpy as np
import rospkg
import rospy

from diff_rigid_body import LocalScene
from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient
from diff_rigid_body_examples import dynamics_fitting, pose_fitting, t_handle, trajectory_energy, trajectory_fitting

Q_HIDDEN = np.array([0.3, -0.4, 1.1, 0.05, -0.1, 0.6])  # the pose to recover
EXACT_ANGLE, EXACT_POSITION = 1e-8, 1e-8  # [rad], [m]: noise-free fit vs Q_HIDDEN
AGREE_ANGLE, AGREE_POSITION = 1e-6, 1e-6  # [rad], [m]: noisy fits, one vs the other
# The T-handle's toss (diff_rigid_body_examples.t_handle): spun about its intermediate axis (z, the grip).
T_HANDLE = t_handle.BODY
FRAME_TIME = t_handle.FRAME_TIME  # [s] between frames, one RK4 step each
FLIP_SUBSTEPS = 4         # RK4 steps per frame for the flip time
START_OFFSETS = (0.1, 0.05, 0.3, 0.3)  # [rad, m, rad/s, m/s] the fits' start, off the hidden toss
AGREE_TRAJECTORY = 1e-6   # max |x_torch - x_least_squares|
NOISE_SIGMAS = 5.0        # max |x_fit - x_hidden| / standard deviation of the estimate
SENSITIVITY_TOLERANCE = 1e-6  # max |S - central differences| / max |S|


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


def t_handle_example(client, noise, frames, drop_dqddot_dq=False):
    """Integrates the tossed T-handle, checks its sensitivities, fits (q0, q0')
    by torch LBFGS and least_squares and reports the flip; returns the list of failures."""
    wall = time.perf_counter()
    bodies = client.bodies()
    i = bodies.names.index(T_HANDLE)
    inertia = bodies.inertias[i]
    x_hidden = t_handle.hidden_toss()
    vertices = np.arange(0, bodies.vertex_counts[i], 4).astype(np.uint32)
    gravity = np.asarray(client.forward_dynamics([T_HANDLE], x_hidden[None, None, :6]).qddot).reshape(6)[3:]
    print('\n3. A tossed T-handle (%s, body %r): %.5f kg, I_b diagonal (%s) kg m^2, %d vertices' % (
        getattr(client, 'server', 'in process, LocalScene'), T_HANDLE, bodies.masses[i],
        ', '.join('%.3e' % v for v in np.diag(inertia)),
        bodies.vertex_counts[i]))
    print('   spun at %.1f rad/s about its intermediate axis (z, the grip), tossed at %.1f m/s; gravity (from '
          'forward_dynamics at rest) (%s) m/s^2' % (np.linalg.norm(t_handle.SPIN), np.linalg.norm(x_hidden[9:]),
                                                   ', '.join('%g' % v for v in gravity)))
    # The hidden toss and its sensitivities, checked against central differences integrated in lockstep.
    start = time.perf_counter()
    states, S = dynamics_fitting.integrate(client, T_HANDLE, x_hidden, FRAME_TIME, frames, sensitivities=True,
                                           drop_dqddot_dq=drop_dqddot_dq)
    integration_time = time.perf_counter() - start
    L = dynamics_fitting.angular_momentum(states, inertia)
    omega = dynamics_fitting.body_rates(states[:, 0:3], states[:, 6:9])
    energy = (0.5 * np.einsum('ka,ab,kb->k', omega, inertia, omega) + 0.5 * bodies.masses[i] * np.sum(
        states[:, 9:12] ** 2, axis=1) - bodies.masses[i] * states[:, 3:6].dot(gravity))
    steps = frames - 1
    print('   RK4 through forward_dynamics: %d frames of %g s (%.2f s), %d stage calls with derivatives in %.2f s; '
          'L conserved to %.1e, energy to %.1e (relative)' % (
              frames, FRAME_TIME, steps * FRAME_TIME, 4 * steps, integration_time,
              np.max(np.linalg.norm(L - L[0], axis=1)) / np.linalg.norm(L[0]),
              np.max(np.abs(energy - energy[0])) / abs(energy[0])))
    h = 1e-6
    batch = np.concatenate([x_hidden[None], x_hidden + h * np.eye(12), x_hidden - h * np.eye(12)])
    start = time.perf_counter()
    moved, _ = dynamics_fitting.integrate(client, T_HANDLE, batch, FRAME_TIME, frames)
    differences = np.transpose(moved[:, 1:13] - moved[:, 13:25], (0, 2, 1)) / (2.0 * h)
    sensitivity_error = np.max(np.abs(differences - S)) / np.max(np.abs(S))
    print('   sensitivities S = ds/ds0 (variational equations from dqddot_dq, dqddot_dqdot) vs central differences '
          'of %d tosses in lockstep (K = %d per call, %.2f s): max |difference| / max |S| = %.1e (max |S| = %.1e)' % (
              len(batch) - 1, len(batch), time.perf_counter() - start, sensitivity_error, np.max(np.abs(S))))
    failures = []
    if not sensitivity_error < SENSITIVITY_TOLERANCE:
        failures.append('T-handle: the sensitivities differ from central differences by %.1e of max |S| (at most %g)'
                        % (sensitivity_error, SENSITIVITY_TOLERANCE))

    # Observations and the two fits.
    rng = np.random.default_rng(7)
    exact = client.positions(T_HANDLE, states[:, :6], vertices)
    observed = exact + noise * rng.normal(size=exact.shape)
    x_start = x_hidden.copy()
    for block, offset in enumerate(START_OFFSETS):
        direction = rng.normal(size=3)
        x_start[3 * block:3 * block + 3] += offset * direction / np.linalg.norm(direction)
    horizons = [frames // 3, 2 * frames // 3, frames]
    print('   observed: %d vertices at %d frames, noise %g m; start off by %.2e rad, %.2e m, %.2e rad/s, %.2e m/s; '
          'fits on the first %s frames in turn' % ((len(vertices), frames, noise) + trajectory_fitting.errors(
              x_start, x_hidden) + (', '.join(str(n) for n in horizons),)))
    print('   %-26s %6s %6s %6s %11s %11s %10s %12s %12s %7s %8s' % (
        'solver', 'iters', 'evals', 'calls', 'rms resid', 'angles', 'position', 'ang. rates', 'velocity', 'sigmas',
        'time'))
    fits = []
    for label, fit in (('torch LBFGS (S, backprop)', dynamics_fitting.fit_torch),
                       ('least_squares (J S)', dynamics_fitting.fit_least_squares)):
        try:
            r = dynamics_fitting.fit_growing(fit, client, T_HANDLE, observed, FRAME_TIME, 1, x_start, horizons,
                                             vertices, drop_dqddot_dq=drop_dqddot_dq)
        except DiffRigidBodyError as e:  # e.g. a trial point at gimbal lock or not finite
            print('   %-26s the node refused a trial point: %s' % (label, e))
            failures.append('T-handle, %s: not converged (the node refused a trial point: %s)' % (label, e))
            return failures
        C = dynamics_fitting.covariance(client, T_HANDLE, r.x, observed, FRAME_TIME, 1, vertices, noise)
        sigma = np.sqrt(np.diag(C))
        sigmas = np.max(np.abs(r.x - x_hidden) / sigma)
        print('   %-26s %6d %6d %6d %8.3e m %6.2e rad %6.2e m %6.2e r/s %6.2e m/s %7.2f %6.2f s%s' % (
            (label, r.iterations, r.evaluations, r.calls, r.residual_rms) + trajectory_fitting.errors(r.x, x_hidden)
            + (sigmas, r.wall_time, '' if r.converged else '  (NOT CONVERGED: %s)' % r.reason)))
        if not r.converged:
            failures.append('T-handle, %s: not converged (%s)' % (label, r.reason))
        elif not sigmas <= NOISE_SIGMAS:
            failures.append('T-handle, %s: %.1f standard deviations from the hidden toss (at most %g)'
                            % (label, sigmas, NOISE_SIGMAS))
        fits.append((label, r, sigma, C))
    difference = np.max(np.abs(fits[0][1].x - fits[1][1].x))
    print('   the two fits differ by %.2e (max over q0, q0\'); standard deviations of the estimate (noise^2 (A^T A)^-1 '
          'at the fit) up to %.1e rad, %.1e m, %.1e rad/s, %.1e m/s' % (
              (difference,) + tuple(np.maximum(fits[0][2], fits[1][2]).reshape(4, 3).max(axis=1))))
    if not difference <= AGREE_TRAJECTORY:
        failures.append('T-handle: the two fits differ by %.2e (at most %g)' % (difference, AGREE_TRAJECTORY))
    linear = trajectory_fitting.fit_least_squares(client, T_HANDLE, observed, np.arange(frames) * FRAME_TIME, x_start,
                                                  vertices)
    print('   for comparison, the ballistic model with linear angles (trajectory_fitting) on the same frames: '
          'rms resid %.3e m' % linear.residual_rms)

    # The flip: when the grip's axis turns perpendicular to L, for the hidden toss and both fits.
    start = time.perf_counter()
    tosses = [x_hidden] + [r.x for _, r, _, _ in fits]
    flips, gradients = dynamics_fitting.flip_times(client, T_HANDLE, tosses, inertia, t_handle.INTERMEDIATE_AXIS,
                                                   FRAME_TIME, frames, FLIP_SUBSTEPS)
    parts = ['hidden toss %.2f ms' % (1e3 * flips[0])]
    for (label, r, _, C), flip, gradient in zip(fits, flips[1:], gradients[1:]):
        deviation = np.sqrt(gradient.dot(C).dot(gradient))
        parts.append('%s %.2f +- %.2f ms' % (label.split(' (')[0], 1e3 * flip, 1e3 * deviation))
        if not abs(flip - flips[0]) <= NOISE_SIGMAS * deviation:
            failures.append('T-handle, %s: flip at %.4f s, %.1f standard deviations from the hidden toss\'s %.4f s'
                            % (label, flip, abs(flip - flips[0]) / deviation, flips[0]))
    print('   flip (the grip\'s axis perpendicular to L): %s (RK4 at %g ms, %d tosses in lockstep, %.2f s)' % (
        ', '.join(parts), 1e3 * FRAME_TIME / FLIP_SUBSTEPS, len(tosses) * 25, time.perf_counter() - start))
    if not np.all(np.isfinite(flips)):
        failures.append('T-handle: no flip within %.2f s' % (steps * FRAME_TIME))
    print('   T-handle example: %.1f s' % (time.perf_counter() - wall))
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--server', default='rigid_body_server')
    parser.add_argument('--body', default='knot', help='body to fit (default: knot)')
    parser.add_argument('--noise', type=float, default=1e-3, help='[m] noise of the noisy fit (default: 1 mm)')
    parser.add_argument('--configurations', type=int, default=1000, help='K (default: 1000)')
    parser.add_argument('--frames', type=int, default=t_handle.FRAMES,
                        help='T of the T-handle fit, frames of 0.02 s (default: %d)' % t_handle.FRAMES)
    parser.add_argument('--t-handle-server', default='/t_handle/rigid_body_server',
                        help='the node serving urdf/t_handle.urdf (default: /t_handle/rigid_body_server)')
    parser.add_argument('--backend', choices=('node', 'local'), default='node',
                        help="example 3 through the t_handle node ('node', default) or in process on a LocalScene "
                             "of urdf/t_handle.urdf ('local')")
    parser.add_argument('--drop-dqddot-dq', action='store_true',
                        help="a wrong gradient: leave dx''/dx out of the T-handle's sensitivities (the demo must fail)")
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node('demo_client', anonymous=True)

    client = RigidBodyClient(args.server).connect()  # persistent connections, opened before any timing
    bodies = print_scene(client)
    failures = pose_fitting_example(client, args.body, [0.0, args.noise])
    trajectory_example(client, bodies, args.configurations)
    if args.backend == 'local':
        t_handle_scene = LocalScene(urdf_path=rospkg.RosPack().get_path('diff_rigid_body') + '/urdf/t_handle.urdf')
    else:
        t_handle_scene = RigidBodyClient(args.t_handle_server).connect()
    failures += t_handle_example(t_handle_scene, args.noise, args.frames, args.drop_dqddot_dq)
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
