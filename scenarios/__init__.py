"""Engine-neutral scene description, shared geometry, scene library and analytic references."""
