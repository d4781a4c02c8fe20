"""The checks the script tests (tests/*_test.py run by CTest) share: each failed check is printed
at once and counted, so that one run reports every failure rather than the first; `result`
prints the verdict and gives the exit code."""


class Checks:
    def __init__(self, name):
        self.name = name
        self.failures = []

    def __call__(self, cond, what):
        if not cond:
            self.failures.append(what)
            print("FAIL:", what)
        return bool(cond)

    def result(self):
        if self.failures:
            print(f"{self.name}: {len(self.failures)} check(s) FAILED")
            return 1
        print(f"{self.name}: all checks passed")
        return 0
