"""PyTorch access to evtac's features (imported only when torch is installed).

:class:`FeatureDataset` is a ``torch.utils.data.Dataset`` over a dataset folder and a
representation: each item is ``(features, labels)``, float32 tensors of 900 and 2 values (pitch,
roll in degrees), the very samples ``evtac train`` trains on (through the dataset's feature
cache). The arrays are computed once, up front, and shared with torch without a copy::

    from torch.utils.data import DataLoader
    import evtac, evtac.torch

    data = evtac.torch.FeatureDataset("dataset/", evtac.Representation("combined"))
    for x, y in DataLoader(data, batch_size=32, shuffle=True):
        ...
"""

from typing import Optional, Sequence, Tuple

import torch
from torch.utils.data import Dataset

import evtac

__all__ = ["FeatureDataset"]


class FeatureDataset(Dataset):
    """The samples of ``trials`` (default: all) of a dataset folder for ``representation``."""

    def __init__(
        self,
        dataset_dir,
        representation: Optional["evtac.Representation"] = None,
        trials: Optional[Sequence[str]] = None,
        motion_points: int = 50,
        stop_points: int = 10,
    ) -> None:
        self.data = evtac.dataset_features(
            dataset_dir, representation, trials, motion_points, stop_points
        )
        self.features = torch.from_numpy(self.data.features)
        self.labels = torch.from_numpy(self.data.labels)

    def __len__(self) -> int:
        return len(self.labels)

    def __getitem__(self, i: int) -> Tuple[torch.Tensor, torch.Tensor]:
        return self.features[i], self.labels[i]
