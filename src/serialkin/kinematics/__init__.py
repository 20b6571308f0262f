"""Forward kinematics and Jacobians (sections 3 and 5), computed by the compiled kernels."""
