"""Validate a results folder's Provenance Run Crate offline with roc-validator.

roc-validator resolves the crate's JSON-LD context (https://w3id.org/ro/crate/1.1/context) over
HTTP through its own cache (requests-cache, SQLite). This machine reaches no web host, so the
cache is seeded from the copy shipped in tests/data/jsonld/ (README.md there says where it is
from) and the validator runs ``--offline``, so nothing is fetched behind one's back. A URL missing from
the cache makes the validator skip the checks that need it (and, for the context, fail the
crate): the test asserts that no check was skipped.

Usage: ``python tests/validate_crate.py results [--files]`` (``make validate-crate``); exit status 0 when
the crate meets every required check of provenance-run-crate-0.5 and tells the folder's truth
(every File listed is there with its sha256 and size, every file of the folder is listed:
:func:`ballbat.pipeline.cratefiles.crate_file_problems`); otherwise exit status 1 and one line
per failed check, naming the check and the file or entity it failed on.
"""

from __future__ import annotations

import io
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


def issue_lines(result) -> list[str]:
    """One line per failed check of roc-validator's ``result``: the check, the entity and property, the message."""
    lines = []
    for issue in result.get_issues():
        check = issue.check
        name = getattr(check, "name", None) or issue.identifier
        where = issue.violatingEntity or "the crate"
        prop = f" ({issue.violatingProperty})" if issue.violatingProperty else ""
        lines.append(f"check failed: {issue.identifier} {name!r} on {where}{prop}: {issue.message}")
    lines += [
        f"check skipped: {c.identifier} {getattr(c, 'name', '')!r} (needs a document not in the cache)"
        for c in result.skipped_checks
    ]
    return lines


def main(argv: list[str]) -> int:
    """Check the crate of the folder named: its files (present, sha256, size, every file listed), then
    roc-validator offline, its cache seeded (not with ``--files``: the files alone, in well under a
    second). Print one line per failed check, naming the check and what it failed on; return 0 when
    all pass, else 1.
    """
    from ballbat.pipeline.cratefiles import crate_file_problems

    files_only = "--files" in argv
    argv = [a for a in argv if a != "--files"]
    crate = Path(argv[0] if argv else "results")
    problems = [f"check failed: {p}" for p in crate_file_problems(crate)]
    if not files_only and (not problems or not problems[0].startswith("check failed: crate ")):
        with tempfile.TemporaryDirectory() as tmp:
            result = validate(crate, seed_cache(Path(tmp) / "http_cache"))
        problems += issue_lines(result)
    for line in problems:
        print(line, file=sys.stderr)
    if problems:
        print(f"{crate}: the crate fails {len(problems)} check(s)", file=sys.stderr)
        return 1
    checks = "every file present and listed"
    checks = checks if files_only else f"{PROFILE}, required level; {checks}"
    print(f"{crate}: the crate passes every check ({checks})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
