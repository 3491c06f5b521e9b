"""Engine adapters: each turns a Scene into a Trajectory."""
