"""``woodcam cache``: where the caches are, how big, and clearing them."""

from __future__ import annotations

import argparse

from .options import uses_settings


def register(subparsers) -> None:
    """Add ``cache info`` and ``cache clear``."""
    from .._cache import CACHE_KIND_TEXT, CACHE_KINDS

    kinds = [f"{CACHE_KIND_TEXT[k]} ({k})" for k in CACHE_KINDS]
    listed = f"{', '.join(kinds[:-1])} and {kinds[-1]}"
    p = subparsers.add_parser(
        "cache", help=f"show or clear woodcam's caches ({', '.join(CACHE_KIND_TEXT[k] for k in CACHE_KINDS)})",
        description=f"woodcam caches {listed} under $WOODCAM_CACHE_DIR (a folder) or the user cache "
        "folder ($XDG_CACHE_HOME/woodcam, ~/.cache/woodcam), keyed by content; the least recently used "
        "entries are dropped above $WOODCAM_CACHE_MAX_MB (default 2048 MiB).")
    sub = p.add_subparsers(dest="cache_command", metavar="ACTION")
    sub.required = True
    info = sub.add_parser("info", help="where the cache is and how much it holds")
    info.set_defaults(func=run_info)
    uses_settings(info, "cache_dir", "cache_max")  # a malformed WOODCAM_WORKERS must not hide the cache
    clear = sub.add_parser("clear", help="delete cache entries (they are rebuilt when needed)")
    clear.add_argument("--kind", default=None, choices=CACHE_KINDS,
                       help=f"only this kind of entry: {' or '.join([', '.join(kinds[:-1]), kinds[-1]])} "
                       "(default: all)")
    clear.set_defaults(func=run_clear)
    uses_settings(clear, "cache_dir")  # a cache can be cleared whatever the other settings say


def run_info(args: argparse.Namespace) -> int:
    from .._cache import cache_max_bytes, cache_root, entries

    files = entries()
    kinds: dict[str, list[int]] = {}
    for f in files:
        kind = f.relative_to(cache_root()).parts[0]
        kinds.setdefault(kind, []).append(f.stat().st_size)
    total = sum(sum(v) for v in kinds.values())
    print(f"{cache_root()}: {len(files)} entries, {total / 2**20:.1f} MiB of "
          f"{cache_max_bytes() / 2**20:.0f} MiB allowed")
    for kind, sizes in sorted(kinds.items()):
        print(f"  {kind:<12} {len(sizes):5d} entries {sum(sizes) / 2**20:10.1f} MiB")
    return 0


def run_clear(args: argparse.Namespace) -> int:
    from .._cache import cache_root, clear

    n, size = clear(args.kind)
    print(f"deleted {n} entries ({size / 2**20:.1f} MiB) from {cache_root()}")
    return 0
