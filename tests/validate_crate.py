"""Validate a results folder's Provenance Run Crate offline with roc-validator.

roc-validator resolves the crate's JSON-LD context (https://w3id.org/ro/crate/1.1/context) over
HTTP through its own cache (requests-cache, SQLite). This machine reaches no web host, so the
cache is seeded from the copy shipped in tests/data/jsonld/ (README.md there says where it is
from) and the validator runs ``--offline``, so nothing is fetched behind one's back. A URL missing from
the cache makes the validator skip the checks that need it (and, for the context, fail the
crate): the test asserts that no check was skipped.

Usage: ``python tests/validate_crate.py results`` (``make validate-crate``); exit status 0 when
the crate meets every required check of provenance-run-crate-0.5.
"""

from __future__ import annotations

import io
import subprocess
import sys
import tempfile
from pathlib import Path

JSONLD = Path(__file__).resolve().parent / "data" / "jsonld"
#: The remote documents the validator needs, and the shipped copy that answers for each.
DOCUMENTS = {"https://w3id.org/ro/crate/1.1/context": JSONLD / "ro-crate-1.1-context.jsonld"}
PROFILE = "provenance-run-crate-0.5"


def seed_cache(cache_path: Path) -> Path:
    """Store the shipped documents in a roc-validator HTTP cache at ``cache_path`` (its ``--cache-path``)."""
    import urllib3
    from requests.adapters import HTTPAdapter
    from requests_cache import CachedSession

    class Shipped(HTTPAdapter):
        """Answer each known URL with its shipped copy; nothing goes to the network."""

        def send(self, request, **kwargs):
            body = DOCUMENTS[request.url].read_bytes()
            raw = urllib3.HTTPResponse(
                body=io.BytesIO(body),
                headers={"Content-Type": "application/ld+json"},
                status=200,
                preload_content=False,
                request_url=request.url,
            )
            return self.build_response(request, raw)

    # the same settings as rocrate_validator.utils.http.HttpRequester's session
    session = CachedSession(
        cache_name=str(cache_path),
        backend="sqlite",
        expire_after=-1,
        allowable_methods=("GET",),
        allowable_codes=(200, 302, 404),
    )
    session.mount("https://", Shipped())
    session.mount("http://", Shipped())
    for url in DOCUMENTS:
        session.get(url).raise_for_status()
    session.close()
    return cache_path


def validate(crate: Path, cache_path: Path):
    """Return roc-validator's result for ``crate`` (offline, required level, the seeded cache)."""
    import warnings

    from rocrate_validator import services
    from rocrate_validator.models import Severity, ValidationSettings

    settings = ValidationSettings(
        rocrate_uri=str(crate),
        profile_identifier=PROFILE,
        requirement_severity=Severity.REQUIRED,
        offline=True,
        cache_path=cache_path,
    )
    with warnings.catch_warnings():  # rdflib/pyshacl deprecations, not ours (pytest makes warnings errors)
        warnings.simplefilter("ignore", DeprecationWarning)
        return services.validate(settings)


def main(argv: list[str]) -> int:
    """Seed a temporary cache and run the ``rocrate-validator`` command offline on the folder named."""
    crate = Path(argv[0] if argv else "results")
    with tempfile.TemporaryDirectory() as tmp:
        cache = seed_cache(Path(tmp) / "http_cache")
        cmd = [
            str(Path(sys.executable).with_name("rocrate-validator")),
            "--no-interactive",
            "validate",
            "--offline",
            "--cache-path",
            str(cache),
            "--profile-identifier",
            PROFILE,
            "--requirement-severity",
            "required",
            "--no-paging",
            str(crate),
        ]
        return subprocess.run(cmd, check=False).returncode


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
