"""The smallest valid case file, shared by the pipeline tests that vary one key of it."""

MINIMAL = """\
dimension: 2
thickness: 0.001
discretization:
  dx: 0.001
materials:
  plate:
    density: 2000
    youngs_modulus: 1.0e9
time:
  end: 1.0e-3
"""
