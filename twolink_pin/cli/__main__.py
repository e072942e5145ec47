"""``python -m twolink_pin.cli``: as the console script, once the package is imported
(``python -m twolink_pin_entry`` is covered from its first statement)."""

from twolink_pin_entry import main

raise SystemExit(main())
