#!/usr/bin/python3
"""Calls every service of rigid_body_server once and prints what comes back."""
import math
import sys

import rospy
from diff_rigid_body.msg import BodyState
from diff_rigid_body.srv import (Backprop, GetBodies, GetMassMatrix, GetState, GetVertexJacobians,
                                 SetState)

SERVER = "/rigid_body_server"


def proxy(name, service_type):
    rospy.wait_for_service(f"{SERVER}/{name}", timeout=30.0)
    return rospy.ServiceProxy(f"{SERVER}/{name}", service_type, persistent=True)


def check(response, what):
    if not response.success:
        raise RuntimeError(f"{what}: {response.message}")
    return response


def matrix(values, rows, cols):
    return "\n".join("    " + " ".join(f"{values[r * cols + c]: .6e}" for c in range(cols)) for r in range(rows))


def main():
    rospy.init_node("demo_client")
    bodies = check(proxy("get_bodies", GetBodies)(), "get_bodies")
    print(f"fixed frame '{bodies.fixed_frame}', bodies:")
    for i, name in enumerate(bodies.names):
        print(f"  {name}: mass {bodies.masses[i]:.6g} kg, {bodies.vertex_counts[i]} vertices, "
              f"COM offset {list(bodies.com_offsets[3 * i:3 * i + 3])}")

    body = bodies.names[0]
    state = check(proxy("get_state", GetState)(bodies=[body]), "get_state").states[0]
    q = list(state.q)
    print(f"\nq({body}) = {q}")
    q[1] = math.pi / 2 - 1e-3  # close to gimbal lock
    check(proxy("set_state", SetState)(states=[BodyState(name=body, q=q)]), "set_state")
    print(f"set_state: theta = pi/2 - 1e-3")

    mass = check(proxy("get_mass_matrix", GetMassMatrix)(bodies=[body], q=[], derivatives=True),
                 "get_mass_matrix")
    print(f"\nM(q) of {body} (cos theta = {mass.cos_theta[0]:.3e}):\n{matrix(mass.mass_matrices, 6, 6)}")
    print(f"dM/dtheta:\n{matrix(mass.derivatives[36:72], 6, 6)}")

    jac = check(proxy("get_vertex_jacobians", GetVertexJacobians)(body=body, vertices=[0, 1], q=[]),
                "get_vertex_jacobians")
    print(f"\nvertex 0 at {jac.positions[0:3]}\nJ_0 = dp/dq:\n{matrix(jac.jacobians[0:18], 3, 6)}")

    gradient = check(proxy("backprop", Backprop)(body=body, vertices=[0, 1], gradients=[0, 0, 1, 0, 0, 1], q=[]),
                     "backprop")
    print(f"\nbackprop of L = z_0 + z_1: dL/dq = {list(gradient.gradient)}")

    refused = proxy("get_vertex_jacobians", GetVertexJacobians)(body="no_such_body", vertices=[], q=[])
    print(f"\nan unknown body is refused: success={refused.success}, message='{refused.message}'")
    return 0


if __name__ == "__main__":
    sys.exit(main())
