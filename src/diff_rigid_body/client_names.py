"""How the clients read names: lists of body names, the node of a pool entry, and what to say
when no node answers to a name.

- A ``bodies`` argument given as one string is one body: ``mass_matrix('knot')`` means
  ``['knot']``, never the bodies 'k', 'n', 'o', 't'.
- A pool entry names a namespace (``/pool1``: the node ``/pool1/rigid_body_server``) or the node
  itself (``/pool1/rigid_body_server``): an entry whose last name is the server's is a node.
- A client whose node does not appear within its timeout raises :class:`NodeNotFoundError`, which
  says whether any node has that name and which rigid_body_server nodes lie below it.
"""
import rosgraph
import rospy

__all__ = ['NodeNotFoundError', 'body_names', 'pool_node_name', 'missing_node_message']


class NodeNotFoundError(rospy.ROSException):
    """No node serves under the name a client was given (not running, or a wrong name)."""


def body_names(values):
    """A string[] request field (bodies, or a pool's entries): [] for None, [values] for one
    name given as a string, else the names in order."""
    if values is None:
        return []
    if isinstance(values, str):
        return [values]
    if isinstance(values, bytes):
        return [values.decode()]
    return [str(value) for value in values]


def pool_node_name(entry, server):
    """The node of pool entry ``entry`` (resolved like any ROS name): ``entry`` itself when its
    last name is ``server``, else ``<entry>/<server>``."""
    trimmed = entry.rstrip('/')
    if trimmed.rsplit('/', 1)[-1] == server:
        return rospy.resolve_name(trimmed)
    return rospy.resolve_name('%s/%s' % (trimmed, server))


def missing_node_message(node, service, timeout):
    """Why ``service`` of ``node`` did not appear within ``timeout`` [s], and what to check."""
    master = rosgraph.Master(rospy.names.get_caller_id())
    try:
        master.lookupNode(node)
        running = True
    except (rosgraph.MasterError, OSError):
        running = False
    try:
        _, _, services = master.getSystemState()
    except (rosgraph.MasterError, OSError):
        services = []
    below = sorted({name[:-len('/get_bodies')] for name, _ in services
                    if name.endswith('/get_bodies') and name.startswith(node.rstrip('/') + '/')})
    if running:
        text = ('node %s is running but did not advertise %s within %g s (is it a rigid_body_server? still '
                'loading its scene?)' % (node, service, timeout))
    else:
        text = 'no node at %s (is it running? rosnode list): %s did not appear within %g s' % (node, service, timeout)
    if below:
        text += "; a client takes the node's name, and below %s there is %s" % (node, ', '.join(below))
    return text
