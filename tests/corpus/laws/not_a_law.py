"""A corpus file with a class that is not a Controller."""


class NotALaw:
    """Just a class."""
