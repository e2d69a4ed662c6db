"""Device protocols: how the controller talks to devices (UPnP, XIRP, OPC UA).

* :mod:`plugnproduce.protocols.upnp`: UPnP on async-upnp-client (``docs/upnp.md``).
* :mod:`plugnproduce.protocols.xirp`: XIRP, XML messages over TCP modelled on VDMA 66430 (``docs/xirp.md``).
* :mod:`plugnproduce.protocols.opcua`: OPC UA on asyncua (``docs/opcua.md``).
* :mod:`plugnproduce.protocols.interface`: the one address every protocol runs on (``--interface``,
  ``PNP_INTERFACE``, loopback by default); a protocol added beside these binds and searches there too.
"""
