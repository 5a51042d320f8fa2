"""PyTorch CPU reference for benches/training.rs and benches/inference.rs.

Same model (900-256-128-64-2 ReLU MLP), loss (SmoothL1, beta 1), optimiser (AdamW lr 5e-3,
wd 1e-4, betas 0.9/0.999, eps 1e-8), batch 32 and data shape (35,000 x 900, a quarter of the
features non-zero) as the Rust benches. Prints the epoch time and single-sample latency
(median, P99, P99.9). Needs `torch` (CPU) in the venv; not used by tests.

`--network stacked` and `--network late` train evtac's learned fusions on 35,000 x 1800 samples
instead (a dense 1800-256-128-64-2 MLP, or two 900-128 branches concatenated before the
256-128-64-2 head, as `evtac.torch.LateFusion`), for `epoch_35000x1800` in benches/training.rs.

Usage: python pytorch_baseline.py [--epochs 2] [--threads 2] [--network mlp|stacked|late]
"""

import argparse
import time

import numpy as np
import torch


class LateFusion(torch.nn.Module):
    """Two 900-128 branches (static frame, dynamic frame), concatenated, then the head."""

    def __init__(self):
        super().__init__()
        self.static_branch = torch.nn.Linear(900, 128)
        self.dynamic_branch = torch.nn.Linear(900, 128)
        self.head = torch.nn.Sequential(
            torch.nn.Linear(256, 128), torch.nn.ReLU(),
            torch.nn.Linear(128, 64), torch.nn.ReLU(),
            torch.nn.Linear(64, 2))

    def forward(self, x):
        s = torch.relu(self.static_branch(x[:, :900]))
        d = torch.relu(self.dynamic_branch(x[:, 900:]))
        return self.head(torch.cat([s, d], dim=1))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--epochs", type=int, default=2)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--samples", type=int, default=35_000)
    parser.add_argument("--density", type=float, default=0.138,
                        help="fraction of non-zero features (its speed does not depend on it)")
    parser.add_argument("--network", choices=["mlp", "stacked", "late"], default="mlp")
    args = parser.parse_args()
    width = 900 if args.network == "mlp" else 1800
    torch.set_num_threads(args.threads)
    torch.set_flush_denormal(True)
    torch.manual_seed(0)
    rng = np.random.default_rng(1)
    n = args.samples
    x = rng.random((n, width), dtype=np.float32)
    x[rng.random((n, width)) >= args.density] = 0.0
    y = rng.uniform(-20, 20, (n, 2)).astype(np.float32)
    x, y = torch.from_numpy(x), torch.from_numpy(y)

    model = LateFusion() if args.network == "late" else torch.nn.Sequential(
        torch.nn.Linear(width, 256), torch.nn.ReLU(),
        torch.nn.Linear(256, 128), torch.nn.ReLU(),
        torch.nn.Linear(128, 64), torch.nn.ReLU(),
        torch.nn.Linear(64, 2))
    opt = torch.optim.AdamW(model.parameters(), lr=5e-3, betas=(0.9, 0.999), eps=1e-8,
                            weight_decay=1e-4)
    loss_fn = torch.nn.SmoothL1Loss(beta=1.0)
    for epoch in range(args.epochs):
        start = time.perf_counter()
        perm = torch.randperm(n)
        for i in range(0, n, 32):
            idx = perm[i:i + 32]
            opt.zero_grad()
            loss = loss_fn(model(x[idx]), y[idx])
            loss.backward()
            opt.step()
        print(f"pytorch {args.network} epoch {epoch + 1} ({n} x {width}, {args.threads} threads): "
              f"{time.perf_counter() - start:.2f} s")

    model.eval()
    samples = [x[i:i + 1].clone() for i in range(64)]
    for threads in sorted({1, args.threads}):
        torch.set_num_threads(threads)
        times = []
        with torch.inference_mode():
            for i in range(20_000):
                t = time.perf_counter()
                model(samples[i % 64])
                times.append((time.perf_counter() - t) * 1e6)
        times.sort()
        q = lambda p: times[round((len(times) - 1) * p)]
        print(f"pytorch single-sample latency ({threads} threads): median {q(0.5):.1f} us, "
              f"P99 {q(0.99):.1f} us, P99.9 {q(0.999):.1f} us")


if __name__ == "__main__":
    main()
