"""The pure-math floor: quaternions, contact frames, closed-form gap kernels and time
profiles. Imports nothing else of the project, so every layer above may use it."""
