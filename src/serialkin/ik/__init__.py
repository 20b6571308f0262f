"""Inverse kinematics: closed-form and numerical solvers behind one interface."""
