"""The exceptions of the odc package."""


class Refused(ValueError):
    """A device file refused by odc's error gate: a diagnostic is at error level.

    ``diagnostics`` holds the error-level diagnostics (dicts, as :func:`odc.check` gives
    them). Allow a rule (``allow=["F107"]``) to go on, as ``odc -A`` does.
    """

    def __init__(self, message, diagnostics):
        super().__init__(message)
        self.diagnostics = diagnostics
