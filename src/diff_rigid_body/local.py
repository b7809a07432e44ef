"""The node's core in the caller's process: :class:`LocalScene` (docs/interface.md, "In process").

    from diff_rigid_body import LocalScene
    scene = LocalScene(urdf_path='robot.urdf')        # or urdf='<robot ...>'
    M = scene.mass_matrix(q=x).M

A local scene answers the state-free methods of
:class:`~diff_rigid_body.client.RigidBodyClient` (the same code: ``client_queries``,
``client_frames``) with the same shapes and result types, and the node's numbers bit for bit: the
compiled module ``diff_rigid_body._local`` calls the very SceneQueries members that the node's
service handlers call. It has no state, so every ``q`` is required (a missing one is refused).
Refusals raise :class:`~diff_rigid_body.client_types.DiffRigidBodyError` with the node's message
(its ``service`` is the node's service name, or ``'load'``). No copies either way: answers are
numpy arrays that own the core's buffers, and C-contiguous float64 inputs are read by the core in
place (do not modify one while a call reads it). Several threads may call one scene at once: the
core runs without the GIL, with one workspace per thread.
"""
import types

from diff_rigid_body.client_names import body_names
from diff_rigid_body.client_queries import SceneQueries

__all__ = ['LocalScene']


def local_services():
    """The services a local scene answers: the node's state-free ones (``_local.SERVICES``, bound
    from the services' declarations)."""
    from diff_rigid_body import _local
    return _local.SERVICES


def package_folder(package):
    """``package://`` resolution as the node's (rospack over ROS_PACKAGE_PATH); "" when unknown."""
    import rospkg
    try:
        return rospkg.RosPack().get_path(package)
    except rospkg.ResourceNotFound:
        return ''


class LocalScene(SceneQueries):
    """A scene loaded in this process from ``urdf_path`` (a file; relative mesh paths from its
    folder) or ``urdf`` (the XML), with the node's load options and defaults (docs/interface.md,
    Parameters): ``geometry`` ('collision' or 'visual'), ``bodies`` (None = all), ``density``
    [kg/m^3] (None = unset), ``joints`` ('model' or 'free'), ``strict_inertia``,
    ``floating_base``, ``fixed_frame`` ('' = the root link, or 'world' with floating_base) and
    ``gravity`` [m/s^2]. A description the node would refuse raises DiffRigidBodyError; an option
    of the wrong form ValueError. ``warnings``: what the node would log at load."""

    def __init__(self, urdf_path=None, urdf=None, geometry='collision', bodies=None, density=None, joints='model',
                 strict_inertia=False, floating_base=False, fixed_frame='', gravity=(0.0, 0.0, -9.81)):
        from diff_rigid_body import _local
        if (urdf_path is None) == (urdf is None):
            raise ValueError('LocalScene: give either urdf_path (a file) or urdf (the XML)')
        self._scene = _local.Scene(urdf if urdf_path is None else str(urdf_path), urdf_path is not None,
                                   geometry=geometry, bodies=body_names(bodies),
                                   density=None if density is None else float(density), joints=joints,
                                   strict_inertia=bool(strict_inertia), floating_base=bool(floating_base),
                                   fixed_frame=fixed_frame or '', gravity=[float(g) for g in gravity],
                                   find_package=package_folder)
        self.warnings = list(self._scene.warnings)

    def call(self, name, **request):
        """Answers service ``name`` in process: the response's fields as attributes (numpy arrays,
        lists of names), or DiffRigidBodyError with the node's message."""
        if name not in local_services():
            raise ValueError('LocalScene answers the state-free services %s, not %r (a local scene has no state)'
                             % (', '.join(local_services()), name))
        return types.SimpleNamespace(**getattr(self._scene, name)(**request))
