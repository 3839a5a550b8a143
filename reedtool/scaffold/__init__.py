"""`new-package`: the frame catalogue, package parameters and template rendering."""
