"""The robot end: a simulated Baxter (pybullet) that detects, completes, plans and executes."""
