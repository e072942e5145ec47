"""A corpus law file that calls ``sys.exit(0)`` while it is imported: an error naming it, not a silent exit 0."""

import sys

sys.exit(0)
