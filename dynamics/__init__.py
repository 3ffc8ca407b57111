"""dynamics: particle and mass-spring simulator, rigid bodies, Pinocchio humanoid."""
