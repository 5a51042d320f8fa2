"""PyTorch access to evtac's features and models (imported only when torch is installed).

:class:`FeatureDataset` is a ``torch.utils.data.Dataset`` over a dataset folder and a
representation: each item is ``(features, labels)``, float32 tensors of 900 (1800 for
``stacked`` and ``late``) and 2 values (pitch, roll in degrees), the very samples ``evtac train``
trains on (through the dataset's feature cache). The arrays are computed once, up front, and
shared with torch without a copy::

    from torch.utils.data import DataLoader
    import evtac, evtac.torch

    data = evtac.torch.FeatureDataset("dataset/", evtac.Representation("combined"))
    for x, y in DataLoader(data, batch_size=32, shuffle=True):
        ...

:func:`load_module` loads a model bundle's ``model.safetensors`` into the PyTorch module that
computes it: :class:`Mlp` (the paper's 900-256-128-64-2, or 1800 inputs for ``stacked``) or
:class:`LateFusion` (``late``: a 900-128 branch per frame, concatenated before the 256-128-64-2
head). Its predictions are evtac's up to float32 rounding::

    net = evtac.torch.load_module("model/")
    pitch_roll = net(torch.from_numpy(features))
"""

import json
from pathlib import Path
from typing import Optional, Sequence, Tuple, Union

import torch
from torch import nn
from torch.utils.data import Dataset

import evtac

__all__ = ["FeatureDataset", "LateFusion", "Mlp", "load_module"]

#: Features of one pooled 30x30 frame.
FRAME = 900


class Mlp(nn.Module):
    """The paper's MLP: ``inputs``-256-128-64-2 with ReLU, its linear layers ``layers.0`` ..
    ``layers.3`` (the names evtac saves)."""

    def __init__(self, inputs: int = FRAME) -> None:
        super().__init__()
        sizes = [inputs, 256, 128, 64, 2]
        self.layers = nn.ModuleList(nn.Linear(a, b) for a, b in zip(sizes, sizes[1:]))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        for i, layer in enumerate(self.layers):
            x = layer(x)
            if i < len(self.layers) - 1:
                x = torch.relu(x)
        return x


class LateFusion(nn.Module):
    """Late fusion of the static and dynamic frames (evtac's ``late`` representation): each
    frame's 900 features through its own ``nn.Linear(900, 128)`` branch and a ReLU, the two
    concatenated (static first) into the paper's head 256-128-64-2. Input: ``(N, 1800)``, the
    static frame's features then the dynamic frame's, as evtac computes them."""

    def __init__(self) -> None:
        super().__init__()
        self.static_branch = nn.Linear(FRAME, 128)
        self.dynamic_branch = nn.Linear(FRAME, 128)
        self.head = nn.Sequential(
            nn.Linear(256, 128), nn.ReLU(), nn.Linear(128, 64), nn.ReLU(), nn.Linear(64, 2)
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        s = torch.relu(self.static_branch(x[:, :FRAME]))
        d = torch.relu(self.dynamic_branch(x[:, FRAME:]))
        return self.head(torch.cat([s, d], dim=1))


def load_module(model_dir: Union[str, Path]) -> nn.Module:
    """The PyTorch module of the bundle in ``model_dir``, its weights loaded (strictly: every
    tensor present, none left over), in evaluation mode."""
    from safetensors.torch import load_file

    model_dir = Path(model_dir)
    representation = json.loads((model_dir / "config.json").read_text())["representation"]
    # Format 1 bundles may hold a bare representation config.
    kind = representation.get("config", representation)["kind"]
    net: nn.Module
    if kind == "late":
        net = LateFusion()
    else:
        net = Mlp(2 * FRAME if kind == "stacked" else FRAME)
    net.load_state_dict(load_file(str(model_dir / "model.safetensors")), strict=True)
    return net.eval()


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
