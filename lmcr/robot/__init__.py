"""The robot: a simulated Baxter (pybullet) that detects the objects on the table, completes an
instruction with them, plans and acts it out (`execute`), talks with a person about it (`dialogue`) and
says what it did (`reply`)."""
