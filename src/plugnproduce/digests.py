"""SHA-256, by which every file kept in the cache folder is named, without loading OpenSSL.

:mod:`hashlib` loads OpenSSL's ``libcrypto``: a few milliseconds of every command's start, about as much as a warm
answer's own work. CPython's own SHA-256 (as :mod:`random` takes its SHA-512) gives the same digests; where the
interpreter has none, hashlib's is used."""

__all__ = ["sha256"]

TYPE_CHECKING = False  # typing itself is not imported: the kept help (helpcache) names its file with this
if TYPE_CHECKING:
    from hashlib import sha256
else:
    try:
        from _sha256 import sha256  # CPython 3.11 (3.12 renamed it: hashlib's is used there)
    except ImportError:
        from hashlib import sha256
