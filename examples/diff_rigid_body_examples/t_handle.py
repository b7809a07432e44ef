"""The tossed T-handle of the demo (urdf/t_handle.urdf), shared by
``nodes/demo_client.py`` and the rviz picture of its flip
(``test/rostest/t_handle_rviz.py``, docs/rviz_t_handle.png).

Body axes: x along the bar (the smallest principal moment), y normal to the
T (the largest), z along the grip (the intermediate one). The toss spins it
mostly about z, so it flips (the Dzhanibekov effect): the grip, up at first,
points down after about 0.55 s. Its angular momentum stays near the vertical,
and the bar axis (x) stays far from it, so theta stays far from gimbal lock
(|theta| < 0.5 rad).
"""
import numpy as np

from diff_rigid_body_examples.dynamics_fitting import rpy_rates

__all__ = ['BODY', 'Q0', 'SPIN', 'VELOCITY', 'FRAME_TIME', 'FRAMES', 'INTERMEDIATE_AXIS', 'hidden_toss']

BODY = 't_handle'
Q0 = np.array([0.05, -0.1, 0.3, -1.18, 0.0, 0.4])  # (phi, theta, psi) [rad], COM [m]
SPIN = np.array([0.15, 0.1, 15.0])  # omega in body axes [rad/s]: mostly about the grip
VELOCITY = np.array([2.0, 0.0, 5.8])  # of the COM [m/s]: back near its start height after 1.18 s
FRAME_TIME = 0.02  # [s] between observed frames (one RK4 step each)
FRAMES = 60  # T: 1.18 s
INTERMEDIATE_AXIS = 2  # z, the grip


def hidden_toss():
    """s0 = (q0, q0') (12,) of the toss: Q0, the angle rates of SPIN, VELOCITY."""
    return np.concatenate([Q0, rpy_rates(Q0[:3], SPIN), VELOCITY])
