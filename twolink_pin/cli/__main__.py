"""``python -m twolink_pin.cli``."""

from twolink_pin.cli import main

raise SystemExit(main())
