"""The case schema, the case-file loader and the driver that chains the stages (see formats.md)."""
