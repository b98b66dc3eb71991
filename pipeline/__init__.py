"""The case schema, the case-file loader, the stages as functions (stages.py) and make's command
line for them (run.py); see formats.md."""
