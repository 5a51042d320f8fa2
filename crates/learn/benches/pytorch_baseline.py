"""PyTorch CPU reference for benches/training.rs and benches/inference.rs.

Same model (900-256-128-64-2 ReLU MLP), loss (SmoothL1, beta 1), optimiser (AdamW lr 5e-3,
wd 1e-4, betas 0.9/0.999, eps 1e-8), batch 32 and data shape (35,000 x 900, a quarter of the
features non-zero) as the Rust benches. Prints the epoch time and single-sample latency
(median, P99, P99.9). Needs `torch` (CPU) in the venv; not used by tests.

Usage: python pytorch_baseline.py [--epochs 2] [--threads 2]
"""

import argparse
import time

import numpy as np
import torch


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--epochs", type=int, default=2)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--samples", type=int, default=35_000)
    parser.add_argument("--density", type=float, default=0.138,
                        help="fraction of non-zero features (its speed does not depend on it)")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    torch.set_flush_denormal(True)
    torch.manual_seed(0)
    rng = np.random.default_rng(1)
    n = args.samples
    x = rng.random((n, 900), dtype=np.float32)
    x[rng.random((n, 900)) >= args.density] = 0.0
    y = rng.uniform(-20, 20, (n, 2)).astype(np.float32)
    x, y = torch.from_numpy(x), torch.from_numpy(y)

    model = torch.nn.Sequential(
        torch.nn.Linear(900, 256), torch.nn.ReLU(),
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
        print(f"pytorch epoch {epoch + 1} ({n} x 900, {args.threads} threads): "
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
