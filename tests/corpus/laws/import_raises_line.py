"""A corpus law file whose import raises at line 5 (a missing dependency)."""


def _needs() -> None:
    raise ImportError("corpus: No module named 'a_package_nobody_installed'")


_needs()
