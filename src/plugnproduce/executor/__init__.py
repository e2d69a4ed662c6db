"""The code executor (paper section 6.3): runs Task State Charts against the devices."""
