"""The PASS/FAIL lines of the Python tests (Checks): run_tests.sh counts them."""


class Checks:
    """The PASS/FAIL lines of a test script: checks(ok, what, detail="") prints
    'PASS  what (detail)' or 'FAIL  what (detail)' and returns bool(ok); the failed ones
    are listed in checks.failed."""

    def __init__(self):
        self.failed = []

    def __call__(self, ok, what, detail=""):
        print(("PASS  " if ok else "FAIL  ") + what + (f" ({detail})" if detail else ""), flush=True)
        if not ok:
            self.failed.append(what)
        return bool(ok)
