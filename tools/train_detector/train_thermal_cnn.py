#!/usr/bin/env python3
"""Trains the thermal classifier (agent/swarm thermal_evidence.hpp ThermalClassifier) on thermal patches.

    python3 train_thermal_cnn.py --patches FILE --out MODEL.onnx [--seed 1] [--epochs 12]
                                 [--threads 2] [--shift-px 2]

swarmbox-fit-thermal --cnn train_thermal_cnn.py runs this (argv, no shell) between gathering its
candidates and fitting the fusion; it needs only python3, numpy and torch (Debian 12:
python3-torch 1.13, scripts/setup_training.sh installs it). Input: the patch file of
swarmbox-fit-thermal (header: 8-byte magic SWBTHERM, uint32 version 1, uint32 px, uint64 count;
then per record int8 label (1 person), uint8 split (0 training, 1 calibration), px x px float32:
ThermalPatchAt's patch, the temperatures around a candidate's ground point minus their median, in
units of 10 K, clamped to [-2, 4]). Output: an ONNX network (opset 11, input N x 1 x px x px float,
dynamic N, output N x 1 logits > 0 for "person") that OpenCV 4.6's cv::dnn reads.

The network: three blocks of 3 x 3 convolution, batch normalisation, ReLU and 2 x 2 max pooling
(16, 32, 64 channels: 40 -> 20 -> 10 -> 5 px), then 64 x 5 x 5 -> 32 -> 1 with dropout 0.3 (the
map keeps where the warm parts lie relative to the candidate). Training: Adam (learning rate 2e-3,
cosine, weight decay 1e-4), binary cross-entropy with the people weighted by others / people (the
classes weigh the same); each batch turned by a random multiple of 90 degrees, mirrored at random
(people lie at any heading) and moved by up to --shift-px pixels (the colour detector places a
candidate a few decimetres off the person). Every draw is seeded; torch.use_deterministic_algorithms.
The weights kept are those of the epoch with the lowest loss on the calibration split (other worlds
and trials than the training split's).
"""
import argparse
import struct
import time

import numpy as np

# The same blocks, torch (train_cnn.py says how to install it when it is missing) and the splits'
# codes (this script's folder is on sys.path).
from train_cnn import CALIBRATION, TRAINING, PatchNet, nn, torch

MAGIC = b"SWBTHERM"
HEADER = struct.Struct("<8sIIQ")


def read_patches(path):
    """(patches N x px x px float32, labels N int8, splits N uint8) of a patch file."""
    with open(path, "rb") as f:
        magic, version, px, count = HEADER.unpack(f.read(HEADER.size))
        if magic != MAGIC or version != 1:
            raise ValueError(f"{path}: not a version-1 SWBTHERM file")
        record = np.dtype([("label", "i1"), ("split", "u1"), ("pixels", "<f4", (px, px))])
        data = np.fromfile(f, dtype=record, count=count)
    if len(data) != count:
        raise ValueError(f"{path}: {len(data)} records of {count}")
    return data["pixels"], data["label"], data["split"]


def augment(x, generator, shift_px):
    """The batch turned by k * 90 degrees, mirrored when m, moved by (dy, dx) (one draw a batch)."""
    k = int(torch.randint(0, 4, (1,), generator=generator))
    m = int(torch.randint(0, 2, (1,), generator=generator))
    x = torch.rot90(x, k, dims=(2, 3))
    if m:
        x = torch.flip(x, dims=(3,))
    if shift_px > 0:
        dy, dx = torch.randint(-shift_px, shift_px + 1, (2,), generator=generator).tolist()
        x = torch.roll(x, (dy, dx), dims=(2, 3))
    return x


def mean_loss(net, x, y, loss_fn):
    net.eval()
    with torch.no_grad():
        total = sum(float(loss_fn(net(x[i:i + 1024]).squeeze(1), y[i:i + 1024])) for i in range(0, len(x), 1024))
    return total / max(len(x), 1)


def train(args):
    torch.manual_seed(args.seed)
    np.random.seed(args.seed)
    torch.use_deterministic_algorithms(True)
    torch.set_num_threads(args.threads)
    t0 = time.monotonic()
    patches, labels, splits = read_patches(args.patches)
    px = patches.shape[1]
    if px % 8 != 0:
        raise ValueError(f"{args.patches}: {px} px patches: three 2 x 2 poolings need a multiple of 8")
    sel = {s: splits == s for s in (TRAINING, CALIBRATION)}
    x = {s: torch.from_numpy(patches[sel[s]]).unsqueeze(1) for s in sel}
    y = {s: torch.from_numpy(labels[sel[s]].astype(np.float32)) for s in sel}
    pos = float(y[TRAINING].sum())
    neg = float(len(y[TRAINING])) - pos
    if pos == 0 or neg == 0 or len(y[CALIBRATION]) == 0:
        raise ValueError(f"{args.patches}: the training split needs people and others, the calibration split patches")
    print(f"train_thermal_cnn: {len(y[TRAINING])} training patches ({int(pos)} people), "
          f"{len(y[CALIBRATION])} calibration ({int(y[CALIBRATION].sum())} people)", flush=True)
    loss_fn = nn.BCEWithLogitsLoss(pos_weight=torch.tensor([neg / pos]), reduction="sum")
    net = PatchNet(px, in_channels=1, dropout=0.3)
    opt = torch.optim.Adam(net.parameters(), lr=2e-3, weight_decay=1e-4)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=args.epochs)
    gen = torch.Generator().manual_seed(args.seed)
    best = (float("inf"), None, -1)
    for epoch in range(args.epochs):
        net.train()
        order = torch.randperm(len(y[TRAINING]), generator=gen)
        for i in range(0, len(order), 128):
            idx = order[i:i + 128]
            opt.zero_grad()
            loss = loss_fn(net(augment(x[TRAINING][idx], gen, args.shift_px)).squeeze(1), y[TRAINING][idx])
            (loss / len(idx)).backward()
            opt.step()
        sched.step()
        cal = mean_loss(net, x[CALIBRATION], y[CALIBRATION], loss_fn)
        print(f"train_thermal_cnn: epoch {epoch + 1}/{args.epochs}: calibration loss {cal:.4f} "
              f"({time.monotonic() - t0:.0f} s)", flush=True)
        if cal < best[0]:
            best = (cal, {k: v.clone() for k, v in net.state_dict().items()}, epoch + 1)
    net.load_state_dict(best[1])
    net.eval()
    torch.onnx.export(net, torch.zeros(1, 1, px, px), args.out, opset_version=11, input_names=["patch"],
                      output_names=["logit"], dynamic_axes={"patch": {0: "n"}, "logit": {0: "n"}})
    print(f"train_thermal_cnn: kept epoch {best[2]} (calibration loss {best[0]:.4f}), wrote {args.out} "
          f"({time.monotonic() - t0:.0f} s)", flush=True)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--patches", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--epochs", type=int, default=12)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--shift-px", type=int, default=2)
    args = p.parse_args()
    if args.epochs < 1 or args.shift_px < 0:
        p.error("--epochs must be >= 1 and --shift-px >= 0")
    train(args)


if __name__ == "__main__":
    main()
