#!/usr/bin/env python3
"""Trains the victim detector's convolutional second stage on the trainer's patches.

    python3 train_cnn.py --patches FILE --out MODEL.onnx [--seed 1] [--epochs 6] [--threads 2]
                         [--widths 16,32,64] [--negatives-per-epoch 24000]
                         [--hard-fraction 0] [--mine-from 3] [--mine-every 3]
                         [--shift-px 0] [--photometric 0]
    python3 train_cnn.py --test-fixture --out tests/agent/swarm/data/patch_cnn_fixture.onnx

swarmbox-train-detector --cnn train_cnn.py runs this (argv, no shell) between its first stage and
its calibration; it needs only python3, numpy and torch (Debian 12: python3-torch 1.13,
scripts/setup_training.sh installs it). Input: the patch file of --export-patches
(tools/train_detector/train_detector.hpp: header, then int8 label, uint8 split, 32 x 32 x 3 uint8
BGR per record). Output: an ONNX network (opset 11, input N x 3 x 32 x 32 float, dynamic N,
output N x 1 logits > 0 for "person") that OpenCV 4.6's cv::dnn reads; the detector feeds it
(pixel - 127.5) / 64 in BGR order (victim_detector_model.hpp kCnnInputMean, kCnnInputScale).

The network: three blocks of 3 x 3 convolution, batch normalisation, ReLU and 2 x 2 max pooling
(--widths channels, default 16, 32, 64; the shipped recipe passes 24, 48, 96: 32 -> 16 -> 8 -> 4
px), then a 16 C -> 32 -> 1 classifier on the 4 x 4 map
(it keeps where things are relative to the candidate's centre, which a global pooling would lose).
Training: Adam (cosine learning rate), each epoch on every positive and a fresh seeded draw of
--negatives-per-epoch negatives (with --hard-fraction F, F of them from the 2 F x that many the
network scored highest at the last mining: epochs --mine-from, then every --mine-every), binary cross-entropy with the positives weighted by negatives /
positives of the epoch (the classes weigh the same), each batch's patches turned by a random multiple of 90 degrees and
mirrored at random (people lie at any heading: the 8 symmetries of the square keep the pixel grid).
Every draw is seeded; torch.use_deterministic_algorithms(True). The weights kept are those of the
epoch with the lowest calibration loss (calibration frames only: never an evaluation seed).
"""
import argparse
import struct
import sys
import time

import numpy as np

try:
    import torch
    from torch import nn
except ImportError:
    sys.stderr.write("train_cnn.py: torch is missing: run scripts/setup_training.sh "
                     "(apt-get install python3-torch) and use Debian's /usr/bin/python3\n")
    sys.exit(3)

MAGIC = b"SWBPATCH"
HEADER = struct.Struct("<8sIIIfQ")
INPUT_MEAN = 127.5
INPUT_SCALE = 1.0 / 64.0
TRAINING, CALIBRATION = 0, 1


def read_patches(path):
    """(patches N x H x W x 3 uint8, labels N int8, splits N uint8) of a patch file."""
    with open(path, "rb") as f:
        magic, version, px, channels, _, count = HEADER.unpack(f.read(HEADER.size))
        if magic != MAGIC or version != 1 or channels != 3:
            raise ValueError(f"{path}: not a version-1 SWBPATCH file")
        record = np.dtype([("label", "i1"), ("split", "u1"), ("pixels", "u1", (px, px, 3))])
        data = np.fromfile(f, dtype=record, count=count)
    if len(data) != count:
        raise ValueError(f"{path}: {len(data)} records of {count}")
    return data["pixels"], data["label"], data["split"]


class PatchNet(nn.Module):
    """The blocks and the classifier above; in_channels 1 and dropout before the last layer for the
    thermal classifier (train_thermal_cnn.py)."""

    def __init__(self, px, widths=(16, 32, 64), in_channels=3, dropout=0.0):
        super().__init__()
        layers = []
        channels = in_channels
        for width in widths:
            layers += [nn.Conv2d(channels, width, 3, padding=1, bias=False), nn.BatchNorm2d(width),
                       nn.ReLU(inplace=True), nn.MaxPool2d(2)]
            channels = width
        self.features = nn.Sequential(*layers)
        side = px // 8
        head = [nn.Flatten(), nn.Linear(channels * side * side, 32), nn.ReLU(inplace=True)]
        if dropout > 0:
            head.append(nn.Dropout(dropout))
        self.classifier = nn.Sequential(*head, nn.Linear(32, 1))

    def forward(self, x):
        return self.classifier(self.features(x))


def to_input(patches):
    """uint8 N x H x W x 3 (BGR) -> float N x 3 x H x W, as cv::dnn::blobFromImages makes it."""
    x = patches.permute(0, 3, 1, 2).float()
    return (x - INPUT_MEAN) * INPUT_SCALE


def augment(x, generator):
    """Each patch turned by k * 90 degrees and mirrored when m (k, m drawn per patch)."""
    k = torch.randint(0, 4, (x.shape[0],), generator=generator)
    m = torch.randint(0, 2, (x.shape[0],), generator=generator)
    out = x.clone()
    for turns in range(4):
        for mirror in range(2):
            sel = (k == turns) & (m == mirror)
            if not bool(sel.any()):
                continue
            y = torch.rot90(x[sel], turns, dims=(2, 3))
            out[sel] = torch.flip(y, dims=(3,)) if mirror else y
    return out


def shift(x, generator, max_px):
    """Each patch moved by (dx, dy) px, both drawn in [-max_px, max_px], its border filled by
    reflection: the first stage's candidate centres miss a person's by a few pixels."""
    if max_px <= 0:
        return x
    n, side = x.shape[0], x.shape[2]
    padded = nn.functional.pad(x, (max_px, max_px, max_px, max_px), mode="reflect")
    dx = torch.randint(0, 2 * max_px + 1, (n,), generator=generator)
    dy = torch.randint(0, 2 * max_px + 1, (n,), generator=generator)
    out = torch.empty_like(x)
    for oy in range(2 * max_px + 1):
        for ox in range(2 * max_px + 1):
            sel = (dx == ox) & (dy == oy)
            if bool(sel.any()):
                out[sel] = padded[sel, :, oy:oy + side, ox:ox + side]
    return out


def photometric(x, generator, amount):
    """Each patch's exposure and white balance changed: pixel p -> clamp(g_c * p + o), the gain
    g_c = (1 + u) (1 + v_c) with u in [-amount, amount] and v_c in [-amount / 2, amount / 2] per
    channel, the offset o in [-32 amount, 32 amount] (pixel units). The world's time of day,
    overcast and exposure vary what one person looks like more than the training draw covers."""
    if amount <= 0:
        return x
    n = x.shape[0]
    u = (torch.rand((n, 1, 1, 1), generator=generator) * 2 - 1) * amount
    v = (torch.rand((n, 3, 1, 1), generator=generator) * 2 - 1) * (amount / 2)
    o = (torch.rand((n, 1, 1, 1), generator=generator) * 2 - 1) * (32 * amount)
    pixels = x / INPUT_SCALE + INPUT_MEAN
    pixels = torch.clamp(pixels * (1 + u) * (1 + v) + o, 0, 255)
    return (pixels - INPUT_MEAN) * INPUT_SCALE


def evaluate(net, x, y, loss_fn, batch):
    """(mean loss, accuracy at logit 0, logits) on x (uint8 patches), y without augmentation."""
    net.eval()
    logits = []
    with torch.no_grad():
        for i in range(0, len(x), batch):
            logits.append(net(to_input(x[i:i + batch])).squeeze(1))
    logits = torch.cat(logits)
    loss = float(loss_fn(logits, y)) / len(x)
    acc = float(((logits > 0).float() == y).float().mean())
    return loss, acc, logits


def mine_hard_negatives(net, x_train, neg_idx, count, t0):
    """The `count` training negatives the network scores highest (its false alarms and near
    misses), by index into x_train: bootstrapping (Sung and Poggio 1998; Felzenszwalb et al.,
    "Object detection with discriminatively trained part-based models", PAMI 2010, 'hard negative
    mining'). Rare look-alikes (a backpack, a plank on rubble) are a small share of the random
    negatives; drawn from this pool they weigh in every epoch."""
    net.eval()
    scores = []
    with torch.no_grad():
        for i in range(0, len(neg_idx), 2048):
            scores.append(net(to_input(x_train[neg_idx[i:i + 2048]])).squeeze(1))
    scores = torch.cat(scores)
    top = torch.topk(scores, min(count, len(scores))).indices
    print(f"train_cnn: mined the {len(top)} hardest of {len(neg_idx)} negatives (logit >= "
          f"{float(scores[top[-1]]):.2f}, {int((scores > 0).sum())} above 0) ({time.monotonic() - t0:.0f} s)",
          flush=True)
    return neg_idx[top]


def train(args):
    torch.manual_seed(args.seed)
    np.random.seed(args.seed)
    torch.use_deterministic_algorithms(True)
    torch.set_num_threads(args.threads)
    t0 = time.monotonic()
    patches, labels, splits = read_patches(args.patches)
    train_sel, cal_sel = splits == TRAINING, splits == CALIBRATION
    # uint8 until a batch is used (a float copy of 100,000 patches would be 1.2 GB).
    x_train, y_train = torch.from_numpy(patches[train_sel]), torch.from_numpy(labels[train_sel].astype(np.float32))
    x_cal, y_cal = torch.from_numpy(patches[cal_sel]), torch.from_numpy(labels[cal_sel].astype(np.float32))
    pos = float(y_train.sum())
    neg = float(len(y_train)) - pos
    print(f"train_cnn: {len(y_train)} training patches ({int(pos)} persons), {len(y_cal)} calibration "
          f"({int(y_cal.sum())} persons), {time.monotonic() - t0:.0f} s", flush=True)
    # Each epoch sees every person and a fresh seeded draw of negatives_per_epoch negatives: over
    # the epochs most of the negatives are seen, at a cost per epoch the shared 2-core machine bears.
    pos_idx = torch.nonzero(y_train > 0.5).squeeze(1)
    neg_idx = torch.nonzero(y_train < 0.5).squeeze(1)
    per_epoch = min(len(neg_idx), args.negatives_per_epoch)
    pos_weight = torch.tensor([per_epoch / max(pos, 1.0)])
    loss_fn = nn.BCEWithLogitsLoss(pos_weight=pos_weight, reduction="sum")
    net = PatchNet(patches.shape[1], args.widths)
    opt = torch.optim.Adam(net.parameters(), lr=args.lr)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=args.epochs)
    gen = torch.Generator().manual_seed(args.seed)
    best = (float("inf"), None, -1)
    hard_count = int(round(args.hard_fraction * per_epoch))
    hard_pool = None  # the negatives the network scored highest at the last mining
    for epoch in range(args.epochs):
        if hard_count > 0 and epoch >= args.mine_from and (epoch - args.mine_from) % args.mine_every == 0:
            hard_pool = mine_hard_negatives(net, x_train, neg_idx, 2 * hard_count, t0)
        net.train()
        drawn = neg_idx[torch.randperm(len(neg_idx), generator=gen)[:per_epoch]]
        if hard_pool is not None:  # part of the draw from the hardest: bootstrapping
            hard = hard_pool[torch.randperm(len(hard_pool), generator=gen)[:hard_count]]
            drawn = torch.cat([drawn[:per_epoch - len(hard)], hard])
        order = torch.cat([pos_idx, drawn])
        order = order[torch.randperm(len(order), generator=gen)]
        total, correct = 0.0, 0
        for i in range(0, len(order), args.batch):
            idx = order[i:i + args.batch]
            xb = augment(to_input(x_train[idx]), gen)
            xb = photometric(shift(xb, gen, args.shift_px), gen, args.photometric)
            logits = net(xb).squeeze(1)
            loss = loss_fn(logits, y_train[idx])
            opt.zero_grad()
            (loss / len(idx)).backward()
            opt.step()
            total += float(loss)
            correct += int(((logits.detach() > 0).float() == y_train[idx]).sum())
        sched.step()
        # The training figures are those of the epoch's batches (augmented, the weights moving): a
        # second pass over 100,000 patches would cost as much as a third of the epoch.
        cal_loss, cal_acc, _ = evaluate(net, x_cal, y_cal, loss_fn, 1024)
        print(f"train_cnn: epoch {epoch + 1}/{args.epochs}: training loss {total / len(order):.4f} "
              f"accuracy {correct / len(order):.4f}, calibration loss {cal_loss:.4f} accuracy {cal_acc:.4f} "
              f"({time.monotonic() - t0:.0f} s)", flush=True)
        if cal_loss < best[0]:
            best = (cal_loss, {k: v.clone() for k, v in net.state_dict().items()}, epoch + 1)
    net.load_state_dict(best[1])
    net.eval()
    print(f"train_cnn: kept epoch {best[2]} (calibration loss {best[0]:.4f})", flush=True)
    return net, patches.shape[1]


def export(net, px, path):
    dummy = torch.zeros(1, 3, px, px)
    torch.onnx.export(net, dummy, path, opset_version=11, input_names=["patches"], output_names=["logits"],
                      dynamic_axes={"patches": {0: "n"}, "logits": {0: "n"}}, do_constant_folding=True)


def fixture_patches(count, px):
    """count uint8 patches N x px x px x 3 from a formula the C++ test repeats (no file needed)."""
    n, i, j, c = np.meshgrid(np.arange(count), np.arange(px), np.arange(px), np.arange(3), indexing="ij")
    return ((n * 31 + i * 7 + j * 13 + c * 29 + i * j) % 256).astype(np.uint8)


def write_test_fixture(seed, px, onnx_path):
    """The unit test's fixture (tests/agent/swarm/data): an untrained PatchNet with seeded weights
    and non-trivial batch-norm statistics, as ONNX, and beside it (.logits.txt) torch's logits for
    fixture_patches(4): cv::dnn must give the same."""
    torch.manual_seed(seed)
    net = PatchNet(px, (16, 32, 64))
    for m in net.modules():
        if isinstance(m, nn.BatchNorm2d):
            m.running_mean.uniform_(-0.5, 0.5)
            m.running_var.uniform_(0.5, 2.0)
    with torch.no_grad():  # logits that differ between the patches by more than the tolerance
        net.classifier[-1].weight.uniform_(-1.0, 1.0)
        net.classifier[1].weight.mul_(4.0)
    net.eval()
    export(net, px, onnx_path)
    with torch.no_grad():
        logits = net(to_input(torch.from_numpy(fixture_patches(4, px)))).squeeze(1)
    with open(onnx_path + ".logits.txt", "w") as f:
        f.write(" ".join(f"{float(v):.6f}" for v in logits) + "\n")
    print(f"train_cnn: wrote the test fixture {onnx_path} (logits {logits.tolist()})")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--patches")
    parser.add_argument("--out", required=True)
    parser.add_argument("--test-fixture", action="store_true",
                        help="write the unit test's untrained fixture network to --out (no --patches)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--epochs", type=int, default=6)
    parser.add_argument("--batch", type=int, default=128)
    parser.add_argument("--lr", type=float, default=2e-3)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--negatives-per-epoch", type=int, default=24000)
    parser.add_argument("--hard-fraction", type=float, default=0.0,
                        help="share of each epoch's negatives drawn from the hardest mined (default 0: none)")
    parser.add_argument("--mine-from", type=int, default=3, help="first epoch (0-based) that mines (default 3)")
    parser.add_argument("--mine-every", type=int, default=3, help="epochs between minings (default 3)")
    parser.add_argument("--widths", type=lambda v: tuple(int(w) for w in v.split(",")), default=(16, 32, 64),
                        help="the three blocks' channels (default 16,32,64)")
    parser.add_argument("--shift-px", type=int, default=0,
                        help="move each training patch by up to this many pixels (default 0: not)")
    parser.add_argument("--photometric", type=float, default=0.0,
                        help="exposure and white-balance jitter, a share (default 0: none; 0.2 = +-20%%)")
    args = parser.parse_args()
    if args.test_fixture:
        write_test_fixture(args.seed, 32, args.out)
        return
    if not args.patches:
        parser.error("--patches is required")
    if len(args.widths) != 3 or min(args.widths) < 1:
        parser.error("--widths takes three channel counts, e.g. 16,32,64")
    if not 0 <= args.shift_px <= 8 or not 0.0 <= args.photometric < 1.0:
        parser.error("--shift-px takes 0-8, --photometric a share in [0, 1)")
    if not 0.0 <= args.hard_fraction < 1.0 or args.mine_from < 1 or args.mine_every < 1:
        parser.error("--hard-fraction takes [0, 1), --mine-from and --mine-every >= 1")
    net, px = train(args)
    export(net, px, args.out)
    print(f"train_cnn: wrote {args.out}", flush=True)


if __name__ == "__main__":
    main()
