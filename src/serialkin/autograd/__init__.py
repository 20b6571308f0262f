"""What :mod:`serialkin.torch` and :mod:`serialkin.jax` share: the numpy side of their operations.

The two public modules wrap :meth:`Robot.fk <serialkin.model.robot.Robot.fk>`,
:meth:`Robot.jacobian <serialkin.model.robot.Robot.jacobian>` and :meth:`Robot.ik
<serialkin.model.robot.Robot.ik>` as differentiable operations of PyTorch and JAX. This
package holds the parts that need neither framework (:mod:`serialkin.autograd.core`):
the forward evaluations in float64 on batches of any leading shape, the IK solve with its
per-row convergence flag, and the implicit-function-theorem cotangent of the IK target.
It imports neither torch nor jax; nothing below the two public modules imports it.
"""
