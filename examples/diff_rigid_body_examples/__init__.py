"""Example optimisers over the diff_rigid_body clients, run by nodes/demo_client.py and
nodes/joint_fit_client.py; each takes a RigidBodyClient or a LocalScene (the same methods).

``pose_fitting``: a body's pose from observed vertices. ``trajectory_fitting``: a tossed
body's (q0, q0') under a ballistic model. ``trajectory_energy``: kinetic energy along a
trajectory from batched mass matrices. ``dynamics_fitting`` and ``t_handle``: the tossed
T-handle fitted through its equations of motion. ``joint_fitting``: an arm's joints.
"""
