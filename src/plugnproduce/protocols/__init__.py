"""Device protocols: how the controller talks to devices (UPnP, XIRP)."""
