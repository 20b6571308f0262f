"""Forward kinematics and Jacobians of the chapter's SCARA (Table 1) and a Puma 560."""

import numpy as np

import serialkin as sk

scara = sk.models.get("scara")
q = np.array([0.3, -0.5, 0.05, 0.2])
print(scara)
print("0T4 (eqs 13-18):\n", np.round(scara.fk(q), 4))

puma = sk.models.get("puma560")
q = puma.random_q(seed=1)
J = puma.jacobian(q)
print("Puma 560 Jacobian rank:", np.linalg.matrix_rank(J))
print("manipulability:", puma.manipulability(q), "condition number:", puma.condition_number(q))

# a batch of a million configurations, on every core
Q = puma.random_q(1_000_000, seed=2)
T = puma.fk(Q)
print("reach of 1e6 random configurations [m]:", np.linalg.norm(T[:, :3, 3], axis=1).max())
