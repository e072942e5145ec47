"""Robot descriptions shipped with twolink-pin (installed as ``twolink_pin.robots``)."""
