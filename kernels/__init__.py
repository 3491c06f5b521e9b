"""The pure-math floor: quaternions, contact frames, closed-form gap kernels, centre-of-mass
frames of body poses and time profiles. Imports nothing else of the project, so every layer
above may use it."""
