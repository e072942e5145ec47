"""A corpus law file that raises while it is imported."""

raise ValueError("corpus: this file refuses to be imported")
