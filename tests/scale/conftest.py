import sys
from pathlib import Path

# _scale_tasks must be importable by worker processes too (loky and Dask pass sys.path on).
sys.path.insert(0, str(Path(__file__).parent))
