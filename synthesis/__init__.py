"""synthesis: people × actions × joint-angle tensors, the N-mode SVD, motion signatures."""
