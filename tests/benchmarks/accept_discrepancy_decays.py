"""Acceptance of the discrepancy stage from ring-downs (issue 31: "the discrepancy stage names a hidden effect from
ring-downs").

Each case: a virtual campaign of three ring-downs of the voltage-driven jointed beam (`tests/_support/decay_campaign.py`:
dwells at the mode reaching 1e-3, 3e-3 and 8e-3 in, cut off, 1.5 s of free decay; the exact Iwan time simulation
with the hidden effect; 0.5% noise), read by the modal stage, calibrated from the ring-downs alone with the
workflow's default config, then `jointcal.discrepancy.diagnose` (the decay path: backbone points, held-out runs,
the rule, GA + posterior recalibration, revalidation by the decays' time simulation). Prints per case: the effect
named, confidence, the time-domain E before and after, the backbone's floor, the named effect's parameter against
the truth's (per unit modal mass of the rig's mode, beam and armature, for k3), the stage's time.

    python tests/benchmarks/accept_discrepancy_decays.py [--rig beam|ministack] [--seeds 1,2,3] [--only NAME]
        [--out FILE]

A channel delay is hidden too: a free decay cannot show it, so 'none' is the right answer from ring-downs (the
stage does not try it and says so).

Measured 2026-11-26 19:47-20:10 UTC on branch rd43 (main 188c3e3 with rdcal merged, 817629e: zeta2's windows, the
ring-down held-out scores as the predictive deviance `jointcal.discrepancy.select.predictive_E`, the calibration's
polish on each window's own standard error), seeds 1-3, the 2-core machine shared with other jobs (load average
4-5). Columns: hidden effect, seed: named, confidence, time-domain E of the calibrated model -> the named model
recalibrated, the floor, right or not, the named effect's recalibrated parameters (truth: k3 3.68e8 per unit modal
mass, loss_ratio 0.3, Fs_drift 0.15, KT_drift 0.1 on the beam; k3 as labelled, c2 1.2 on the Ministack), the stage's
time, the baseline's and the top two candidates' held-out scores. The beam (voltage):

    none           s1: none           high   E  0.82 -> 0.76 ( -8%)  floor 0.02  ok                                      27 s  held-out: baseline 1.00, cubic 1.08, elastic 1.10
    none           s2: none           high   E  0.84 -> 0.78 ( -8%)  floor 0.00  ok                                      24 s  held-out: baseline 0.91, elastic 0.95, cubic 1.03
    none           s3: none           high   E  0.64 -> 0.57 (-11%)  floor 0.01  ok                                      23 s  held-out: baseline 0.84, elastic 0.86, cubic 0.95
    cubic          s1: cubic          high   E 10.00 -> 0.76 (-92%)  floor 0.10  ok   k3 3.8e+08                         13 s  held-out: baseline 6.89, cubic 1.11, settling 4.53
    cubic          s2: cubic          high   E 27.32 -> 0.80 (-97%)  floor 0.04  ok   k3 3.74e+08                        10 s  held-out: baseline 8.54, cubic 1.02, settling 8.46
    cubic          s3: cubic          high   E 21.09 -> 0.59 (-97%)  floor 0.06  ok   k3 3.67e+08                        10 s  held-out: baseline 9.40, cubic 0.94, settling 9.18
    elastic        s1: elastic        high   E  6.44 -> 0.87 (-87%)  floor 0.03  ok   loss_ratio 0.316                   11 s  held-out: baseline 6.83, elastic 1.16, cubic 4.50
    elastic        s2: elastic        medium E  6.41 -> 3.31 (-48%)  floor 0.05  ok   loss_ratio 0.263                   13 s  held-out: baseline 6.50, elastic+cubic 1.79, elastic 2.13
    elastic        s3: elastic        high   E  6.21 -> 0.67 (-89%)  floor 0.02  ok   loss_ratio 0.301                   12 s  held-out: baseline 5.95, elastic 0.89, cubic 4.98
    settling       s1: settling       high   E 11.59 -> 0.69 (-94%)  floor 0.02  ok   Fs_d -0.124; KT_d 0.0224; n_settle 3.42 10 s  held-out: baseline 17.48, settling 1.47, cubic 17.82
    settling       s2: settling       high   E 12.46 -> 0.76 (-94%)  floor 0.01  ok   Fs_d -0.0209; KT_d 0.0191; n_settle 2.94 11 s  held-out: baseline 18.77, settling 1.28, cubic 19.12
    settling       s3: settling       medium E 11.51 -> 0.64 (-94%)  floor 0.01  ok   Fs_d -0.151; KT_d 0.0206; n_settle 3.03 12 s  held-out: baseline 17.56, settling+elastic 5.48, settling+cubic 5.68
    channel_delay  s1: none           high   E  0.82 -> 0.76 ( -8%)  floor 0.02  ok                                       9 s  held-out: baseline 1.02, elastic 1.04, cubic 1.13
    channel_delay  s2: none           high   E  0.85 -> 0.79 ( -8%)  floor 0.00  ok                                       9 s  held-out: baseline 0.92, elastic 0.94, cubic 1.04
    channel_delay  s3: none           high   E  0.71 -> 0.65 ( -9%)  floor 0.02  ok                                      25 s  held-out: baseline 0.89, elastic 0.91, cubic 1.05
    elastic+cubic  s1: cubic+elastic  high   E  8.78 -> 0.74 (-92%)  floor 0.22  ok   k3 3.99e+08; loss_ratio 0.263      48 s  held-out: baseline 7.93, cubic+elastic 1.25, cubic 3.99
    elastic+cubic  s2: cubic+elastic  high   E  7.96 -> 1.00 (-87%)  floor 0.31  ok   k3 3.79e+08; loss_ratio 0.297      49 s  held-out: baseline 7.04, cubic+elastic 1.72, cubic 3.97
    elastic+cubic  s3: cubic+elastic  high   E  7.91 -> 0.61 (-92%)  floor 0.17  ok   k3 3.6e+08; loss_ratio 0.306       34 s  held-out: baseline 8.14, cubic+elastic 1.03, cubic+settling 3.69

The Ministack (--rig ministack):

    none           s1: none           high   E  1.11 -> 0.79 (-28%)  floor 0.01  ok                                      42 s  held-out: baseline 0.81, quad 0.80, gain 0.82
    none           s2: none           high   E  1.10 -> 0.77 (-29%)  floor 0.03  ok                                      38 s  held-out: baseline 0.80, gain 0.81, quad 0.82
    none           s3: none           high   E  1.08 -> 0.75 (-31%)  floor 0.01  ok                                      36 s  held-out: baseline 0.78, quad 0.80, cubic 0.81
    cubic 5e11     s1: cubic          high   E  1.85 -> 0.80 (-57%)  floor 0.03  ok   k3 5.2e+11                         75 s  held-out: baseline 1.90, cubic 0.87, quad 1.85
    cubic 5e11     s2: cubic          high   E  1.81 -> 0.82 (-54%)  floor 0.10  ok   k3 4.82e+11                        73 s  held-out: baseline 1.62, cubic 0.88, settling 1.69
    cubic 5e11     s3: cubic          high   E  1.75 -> 0.73 (-58%)  floor 0.05  ok   k3 4.76e+11                        64 s  held-out: baseline 1.82, cubic 0.81, quad 1.75
    cubic 2e12     s1: cubic          high   E  3.86 -> 0.70 (-82%)  floor 0.02  ok   k3 2.01e+12                        60 s  held-out: baseline 4.14, cubic 0.76, quad 2.78
    cubic 2e12     s2: cubic          high   E  3.86 -> 0.76 (-80%)  floor 0.03  ok   k3 1.99e+12                        54 s  held-out: baseline 3.29, cubic 0.79, settling 3.32
    cubic 2e12     s3: cubic          high   E  3.94 -> 0.70 (-82%)  floor 0.07  ok   k3 1.99e+12                        52 s  held-out: baseline 3.98, cubic 0.78, quad 2.53
    quad_damping   s1: quad_damping   high   E  6.26 -> 3.51 (-44%)  floor 0.02  ok   c2 1.11                            70 s  held-out: baseline 7.52, quad 0.82, cubic 5.00
    quad_damping   s2: quad_damping   high   E  6.30 -> 0.74 (-88%)  floor 0.02  ok   c2 1.2                             58 s  held-out: baseline 7.51, quad 0.80, cubic 7.37
    quad_damping   s3: quad_damping   high   E  6.19 -> 0.72 (-88%)  floor 0.03  ok   c2 1.18                            68 s  held-out: baseline 7.46, quad 0.79, cubic 4.71
    channel_delay  s1: none           high   E  1.09 -> 0.72 (-34%)  floor 0.01  ok                                      48 s  held-out: baseline 0.76, gain 0.77, quad 0.78
    channel_delay  s2: none           high   E  1.10 -> 0.76 (-31%)  floor 0.02  ok                                      47 s  held-out: baseline 0.79, quad 0.81, gain 0.82
    channel_delay  s3: none           high   E  1.11 -> 0.72 (-35%)  floor 0.02  ok                                      47 s  held-out: baseline 0.78, gain 0.76, quad 0.79

The right name in 33 of 33 campaigns (18 beam, 15 Ministack; 'none' for every 'none' and channel_delay); high in 31,
medium in two beam rows: elastic_softening seed 2 (held-out 2.13 > HIGH_SCORE; the pair 1.79, not under MARGIN x
2.13) and joint_settling seed 3 (5.97). Against the earlier numbers here: the beam's cubic seed 1, medium on zeta2
(held-out 2.10, its top fold the refit's extrapolation), is high at 1.11; cubic seed 3, medium on main (floor 3.23),
is high (floor 0.06); joint_settling seed 3, high on main (floor 0.08), is medium now by its score (5.97 >
HIGH_SCORE; its pairs 5.48, 5.68; E still falls 94%); elastic_softening seed 2, high on main, is medium; the
Ministack's 'none' and channel_delay seed 2, wrong on zeta2 with the log-amplitude weighting and medium with the
windows alone, are right and high (baselines 0.79-0.80); E before of the right model ('none') is 0.64-0.84 on the
beam and 1.08-1.11 on the Ministack (main 0.80-1.13 and 1.51-1.76: the calibration's polish on the windows' standard
errors). Every k3 within 5% of the truth on the Ministack, 0.3-8% on the beam; c2 1.11-1.2.

NOT met in two rows, though named right: the named model recalibrated does not validate, E after 3.31 (beam
elastic_softening seed 2; main 8.09 -> 1.03, high, also on 188c3e3 re-run today) and 3.51 (Ministack
quadratic_damping seed 1, still printed high: `confirm` only asks that E fall; main 12.30 -> 0.88, and 0.88 on
188c3e3 re-run today). Both fail on the top ring-down alone (per level E 1.10 / 1.10 / 5.53 on the beam; 0.98 / 1.03
/ 1.31 / 6.75 on the Ministack) while the recalibrated fast model fits at E 0.90 and 0.78 and the floor at the named
candidate's fit is 0.05 and 0.02: the recalibration's GA (30 generations, best E 2.69 and 3.28; main's Ministack run
stopped at 8, best 0.878) ended in a valley whose macroslip knee sits on the top measured amplitude (phi_max 6.28e-3
in against the top window's 6.31e-3 in on the beam, 8.39e-5 against 8.44e-5 on the Ministack; main's recalibrated
Ministack model phi_max 3.9e-3, all in microslip), where the steady backbone with its read-out factor is not what
the time simulation's decay reads. The calibration's knee rule (`jointcal.calibrate.fit.pick_polished`) is not
applied by `jointcal.discrepancy.recalibrate`, nor is the floor taken at the recalibrated optimum. Open; not changed
here.

Measured 2026-11-26 14:35-15:30 UTC on branch zeta2, the ring-down windows grown towards 0.5% standard error of
the decay rate (`jointcal.measure.ringdown.ZETA_SE_AIM`: fewer, longer windows at the bottom of each decay), the
machine shared with other jobs. With the windows alone (the branch's head), beam seed 1: cubic_stiffening right
but medium (held-out score 2.10 > HIGH_SCORE: folds 1.15 / 0.65 / 3.31; main 1.45 = 0.80 / 0.72 / 2.21); none
right and high; Ministack 'none' seed 2 right but medium (baseline 1.44, sensor_gain 1.14, under 0.8 x 1.44).
The top fold is the refit's own extrapolation: the cubic refit on the two lower runs (k3 3.42e8 against 3.76e8
on all) predicts the top run's first three windows -8.7, -5.9, -3.1 sigma off in f, where the Gauss-Newton
predictive sd from the lower runs' noise is 6.8, 4.3, 2.3 (main: -6.5, -4.8, -2.4 against 7.6, 4.3, 2.4); scaled
by sqrt(1 + sd^2) the fold reads 1.05 (main 1.08). Weighted per window, the grown windows left 6 points in that
run (main 10), the top three of them half of its mean, and sigma_f at its floor (0.007-0.009%, main the windows'
own 0.010-0.016%): the right model's expected top-fold E from those sd is 2.7 (main's tiling 2.35).

Tried and reverted (dfdf705, d49a763): each window weighted within its run by its share of the log-amplitude, in
the validation's E and the objective alike (expected top-fold E 2.06 and 1.97 with either tiling). The beam, seed 1:

    none                                 seed 1: none                                 high   E   3.44 ->  0.79 ( -77%)  floor 0.03  ok
    cubic_stiffening                     seed 1: cubic_stiffening                     high   E  22.20 ->  0.83 ( -96%)  floor 0.06  ok   k3 3.78e+08 (truth 3.68e+08)
    elastic_softening                    seed 1: elastic_softening                    high   E  11.18 ->  0.99 ( -91%)  floor 0.03  ok   loss_ratio 0.317 (truth 0.3)
    joint_settling                       seed 1: joint_settling                       high   E  17.41 ->  0.66 ( -96%)  floor 0.02  ok   Fs_drift -0.196 (truth 0.15); KT_drift 0.0237 (truth 0.1); n_settle 3.56
    channel_delay                        seed 1: none                                 high   E   4.22 ->  0.80 ( -81%)  floor 0.03  ok
    elastic_softening+cubic_stiffening   seed 1: elastic_softening+cubic_stiffening   medium E  17.43 ->  0.86 ( -95%)  floor 0.07  ok   loss_ratio 0.264 (truth 0.3); k3 3.96e+08 (truth 3.68e+08)

The Ministack, seeds 1-2:

    none                                 seed 1: none                                 high   E   3.87 ->  0.81 ( -79%)  floor 0.01  ok
    none                                 seed 2: unexplained                          low    E   4.39 ->  1.55 ( -65%)  floor 0.14  MISS
    cubic_stiffening                     seed 1: cubic_stiffening                     high   E   2.40 ->  0.94 ( -61%)  floor 0.05  ok   k3 4.93e+11 (truth 5e+11)
    cubic_stiffening                     seed 2: cubic_stiffening                     high   E  20.40 ->  0.90 ( -96%)  floor 0.10  ok   k3 4.96e+11 (truth 5e+11)
    cubic_stiffening                     seed 1: cubic_stiffening                     high   E  16.55 ->  0.74 ( -96%)  floor 0.04  ok   k3 1.98e+12 (truth 2e+12)
    cubic_stiffening                     seed 2: cubic_stiffening                     high   E  27.28 ->  0.85 ( -97%)  floor 0.03  ok   k3 2.02e+12 (truth 2e+12)
    quadratic_damping                    seed 1: quadratic_damping                    high   E  18.48 ->  0.84 ( -95%)  floor 0.03  ok   c2 1.19
    quadratic_damping                    seed 2: quadratic_damping                    high   E  19.20 ->  0.84 ( -96%)  floor 0.07  ok   c2 1.2
    channel_delay                        seed 1: none                                 high   E   2.95 ->  0.79 ( -73%)  floor 0.02  ok
    channel_delay                        seed 2: quadratic_damping                    high   E   3.08 ->  1.15 ( -63%)  floor 0.11  MISS c2 1.76e-10

The pair stays medium at 2.19 (folds 2.06 / 0.66 / 2.93: errors -12.2, -7.3, -2.2 sigma against predictive sd
13.3, 7.6, 3.4), and the weight moved to the long bottom windows turned two of the Ministack's seed-2 campaigns
without a visible effect wrong (baseline 1.74 with its 10 g fold 2.82; the time-domain E after 1.55, 1.24 per
window). Open: a held-out point's error scaled by sqrt(sigma^2 + the refit's predictive variance there) reads
1.05-1.12 on every fold of the beam's cubic and pair; it would change the rule's scale (NONE_E, HIGH_SCORE were
set on scores that include that uncertainty) and is not tried here.

Measured 2026-11-26 13:40-14:00 UTC on main with the floor the smaller of the baseline's and the best single
effect's fold floor (a model that misses an effect bends to each fold, far from its fit on all runs where its
factor was taken: that error is the model's; before, the baseline's alone), the machine shared with one other job.
The Ministack, seeds 1-3:

    none                      seed 1: none               high   E  1.51 -> 0.88 (-42%)  floor 0.01  ok
    none                      seed 2: none               high   E  1.76 -> 0.83 (-53%)  floor 0.01  ok
    cubic_stiffening k3 5e11  seed 1: cubic_stiffening   high   E  6.00 -> 1.11 (-82%)  floor 0.05  ok  k3 4.25e+11
    cubic_stiffening k3 5e11  seed 2: cubic_stiffening   high   E 30.57 -> 3.66 (-88%)  floor 0.05  ok  k3 3.85e+11
    cubic_stiffening k3 5e11  seed 3: cubic_stiffening   high   E 27.74 -> 1.53 (-94%)  floor 0.03  ok  k3 4.12e+11
    cubic_stiffening k3 2e12  seed 1: cubic_stiffening   high   E 19.67 -> 2.19 (-89%)  floor 0.04  ok  k3 1.96e+12
    cubic_stiffening k3 2e12  seed 2: cubic_stiffening   high   E 26.75 -> 2.67 (-90%)  floor 0.04  ok  k3 1.93e+12
    cubic_stiffening k3 2e12  seed 3: cubic_stiffening   high   E  2.71 -> 0.79 (-71%)  floor 0.02  ok  k3 2.01e+12
    quadratic_damping         seed 1: quadratic_damping  high   E 12.30 -> 0.88 (-93%)  floor 0.00  ok  c2 1.18 (truth 1.2)
    quadratic_damping         seed 2: quadratic_damping  high   E 12.59 -> 0.92 (-93%)  floor 0.06  ok  c2 1.2
    channel_delay             seed 1: none               high   E  1.68 -> 0.85 (-49%)  floor 0.01  ok
    channel_delay             seed 2: none               high   E  2.95 -> 0.87 (-70%)  floor 0.03  ok

Stages 33-103 s (calibration and diagnosis). The beam, seed 1, every row right and high (stages 14-19 s): none
0.81 -> 0.77; cubic 14.03 -> 0.87 (k3 3.78e8, truth 3.68e8); elastic_softening 7.82 -> 0.93 (loss_ratio 0.304);
joint_settling 10.16 -> 0.84 (its drifts not identified: Fs_drift -0.146 against +0.15, KT_drift 0.024 against
0.1: one level per ring-down and place in the sequence, so drift and amplitude trade); channel_delay none; the pair
both named, 10.83 -> 0.86 (k3 3.97e8, loss_ratio 0.258), floor 0.35.

Before it, 13:00 UTC, the branch rebased on main (the ring-down read-out's junction fix, 29e8131, and its
window fit in numba, 64cf86c; the calibration from the ring-downs lands elsewhere, so the campaigns' E before
moved), on the 2-core machine shared with two other jobs. The Ministack:

    cubic_stiffening k3 5e11  seed 1: unexplained        low    E  6.00 -> 1.61 (-73%)  floor 1.28   MISS
    cubic_stiffening k3 5e11  seed 2: cubic_stiffening   high   E 30.57 -> 3.66 (-88%)  floor 0.08   ok  k3 3.85e+11
    cubic_stiffening k3 5e11  seed 3: cubic_stiffening   high   E 27.74 -> 1.53 (-94%)  floor 0.11   ok  k3 4.12e+11
    cubic_stiffening k3 2e12  seed 1: cubic_stiffening   medium E 19.67 -> 2.19 (-89%)  floor 1.44   ok  k3 1.96e+12
    cubic_stiffening k3 2e12  seed 2: cubic_stiffening   medium E 26.75 -> 2.67 (-90%)  floor 15.74  ok  k3 1.93e+12
    cubic_stiffening k3 2e12  seed 3: cubic_stiffening   high   E  2.71 -> 0.79 (-71%)  floor 0.11   ok  k3 2.01e+12
    none                      seed 1: none               high   E  1.51 -> 0.88 (-42%)  floor 0.01   ok
    quadratic_damping         seed 1: quadratic_damping  high   E 12.30 -> 0.88 (-93%)  floor 0.07   ok  c2 1.18 (truth 1.2)
    channel_delay             seed 1: none               high   E  1.68 -> 0.85 (-49%)  floor 0.01   ok

The cubic spring named in 5 of 6 (high in 3), E falling 71-94%; main names it in none. The two medium rows have a
fold floor over FLOOR_HIGH (1.44; 15.74: a held-out fold's refit left the full fit's valley, where the factor taken
at the full fit no longer holds), the miss is the weaker spring whose calibration (E 6.00) the baseline's and the
cubic's held-out scores do not separate by the floor. The beam, seed 1: every row right and high (none 0.81 ->
0.77; cubic 14.03 -> 0.87, k3 3.78e8 against 3.68e8; elastic_softening 7.82 -> 0.93, loss_ratio 0.304; joint_settling
10.16 -> 0.84; channel_delay none; the pair named both, 10.83 -> 0.86, k3 3.97e8, loss_ratio 0.258), stages 32-54 s.

Before the rebase, on branch decay-factor (the read-out factor, `jointcal.discrepancy.decay_readout`: each point
predicted as the estimator reads the candidate's simulated ring-down, f_bb(q; theta) x f_read / f_bb at theta_ref,
zeta likewise, retaken at each optimum; every candidate scored from the calibration and its other valleys; the
floor the linearised fast model against the time simulation's read-out at each held-out fold's refit), on a loaded
2-core machine. Columns: hidden effect, seed: named, confidence, time-domain E of the calibrated model -> the
named model recalibrated, the floor, right or not, the named effect's recalibrated parameters, the stage's time
(calibration and diagnosis, as `run_case` times them).

The base-driven Ministack (--rig ministack; four ring-downs 0.3-10 g, 0.1% noise):

    cubic_stiffening k3 2e+12  seed 1: cubic_stiffening   high   E 16.63 -> 0.78 (-95%)  floor 0.13  ok  k3 2e+12 (truth 2e+12)     stage 221 s
    cubic_stiffening k3 2e+12  seed 2: cubic_stiffening   high   E  2.33 -> 0.79 (-66%)  floor 0.11  ok  k3 1.96e+12 (truth 2e+12)  stage 226 s
    cubic_stiffening k3 2e+12  seed 3: cubic_stiffening   high   E 19.30 -> 0.78 (-96%)  floor 0.12  ok  k3 1.99e+12 (truth 2e+12)  stage 223 s
    cubic_stiffening k3 5e+11  seed 1: cubic_stiffening   high   E  2.10 -> 0.84 (-60%)  floor 0.07  ok  k3 4.89e+11 (truth 5e+11)  stage 228 s
    none                       seed 1: none               high   E  1.87 -> 0.87 (-53%)  floor 0.02  ok                             stage 182 s
    none                       seed 2: none               high   E  2.18 -> 0.83 (-62%)  floor 0.04  ok                             stage 184 s
    quadratic_damping          seed 1: quadratic_damping  high   E 12.27 -> 0.87 (-93%)  floor 0.21  ok  c2 1.19 (truth 1.2)         stage 209 s

Before (main f0afb94: the backbone alone, the floor the backbone against the calibrated model's time simulation):
'unexplained' on seeds 1 and 2 (floors 1.39 and 19.6, the previous session's run), and at seed 5 (k3 5e11 and 2e12,
the table below) 'unexplained', low, E 2.32 -> 1.97 and 27.74 -> 26.27; main's floor on seeds 1 and 3 here (the
same function, kept as ``backbone_at_calibration``) is 11.1 and 12.4. Steps on this branch: with the factor alone
(no valley starts, the floor taken across the baseline's refit) seed 1 gave cubic_stiffening, medium, E 16.63 ->
2.26, floor 5.4, and seed 2 the pair quadratic_damping+cubic_stiffening, low (E 2.33 -> 3.03), seed 3
'unexplained' (E 19.30 -> 4.77, floor 5.3). The three cubic campaigns of 2e12 end at E 0.78-0.79,
the noise's level; seed 2's calibration (E 2.33 before) and the weaker spring (5e11, E 2.10 before) leave less to
take out, so E falls by 60-66% there, to the same level. What it took: (1) the factor -- the calibrated Iwan's
backbone against its own time simulation read by the estimator was E 11-12 (the macroslip knee at the top amplitude
read: its first windows read zeta 0.047 where the backbone gives 0.024); (2) the starts -- beta is held in every
fit, and the Iwan alone made to follow a hardening backbone sits at Fs 46-50, beta 0.9 with its knee at the top
amplitude; from there the cubic candidate's least squares stayed in that valley (held-out 10.7 on seed 3, the
factor's fixed point oscillating, its time-simulated E 8.4-9.1 over four refreshes), from the GA's valley at Fs 480,
beta 0.001 (truth Fs 313, beta 0.004) it fits to E 0.79, held-out 0.81; (3) the floor -- taken across the baseline's
refit it compared two valleys (11.7) and turned the decision to 'none'; taken at the folds' refits it is 0.1-0.2.

The jointed beam (voltage; the default --rig beam):

    none                                 seed 1: none                                 high   E   0.80 ->  0.76 (  -5%)  floor 0.02  ok     stage 71 s
    none                                 seed 2: none                                 high   E   1.13 ->  0.92 ( -18%)  floor 0.01  ok     stage 71 s
    none                                 seed 3: none                                 high   E   0.84 ->  0.79 (  -6%)  floor 0.01  ok     stage 66 s
    cubic_stiffening                     seed 1: cubic_stiffening                     high   E  14.24 ->  0.88 ( -94%)  floor 0.21  ok   k3 3.76e+08 (truth 3.68e+08)  stage 79 s
    cubic_stiffening                     seed 2: cubic_stiffening                     high   E  12.92 ->  0.88 ( -93%)  floor 0.23  ok   k3 3.71e+08 (truth 3.68e+08)  stage 77 s
    cubic_stiffening                     seed 3: cubic_stiffening                     medium E  15.82 ->  0.77 ( -95%)  floor 3.23  ok   k3 3.6e+08 (truth 3.68e+08)  stage 80 s
    elastic_softening                    seed 1: elastic_softening                    high   E   7.83 ->  0.93 ( -88%)  floor 0.11  ok   loss_ratio 0.301 (truth 0.3)  stage 72 s
    elastic_softening                    seed 2: elastic_softening                    high   E   8.09 ->  1.03 ( -87%)  floor 0.14  ok   loss_ratio 0.266 (truth 0.3)  stage 75 s
    elastic_softening                    seed 3: elastic_softening                    high   E   8.52 ->  0.85 ( -90%)  floor 0.13  ok   loss_ratio 0.301 (truth 0.3)  stage 79 s
    joint_settling                       seed 1: joint_settling                       high   E  10.20 ->  0.81 ( -92%)  floor 0.06  ok   Fs_drift 1 (truth 0.15); KT_drift 0.386 (truth 0.1); n_settle 4.05  stage 82 s
    joint_settling                       seed 2: joint_settling                       high   E  11.04 ->  0.84 ( -92%)  floor 0.20  ok   Fs_drift -0.0118 (truth 0.15); KT_drift 0.018 (truth 0.1); n_settle 2.8  stage 73 s
    joint_settling                       seed 3: joint_settling                       high   E  11.20 ->  0.76 ( -93%)  floor 0.08  ok   Fs_drift -0.162 (truth 0.15); KT_drift 0.0206 (truth 0.1); n_settle 2.95  stage 88 s
    channel_delay                        seed 1: none                                 high   E   0.80 ->  0.76 (  -5%)  floor 0.02  ok     stage 55 s
    elastic_softening+cubic_stiffening   seed 1: cubic_stiffening+elastic_softening   high   E  10.88 ->  0.87 ( -92%)  floor 0.33  (ok)  k3 3.93e+08 (truth 3.68e+08); loss_ratio 0.261 (truth 0.3)  stage 92 s
    elastic_softening+cubic_stiffening   seed 2: elastic_softening+cubic_stiffening   high   E  10.32 ->  0.92 ( -91%)  floor 0.27  ok   loss_ratio 0.238 (truth 0.3); k3 4.18e+08 (truth 3.68e+08)  stage 65 s

The right effects in 15 of 15 rows run (not run this time, for time: channel_delay seeds 2-3, the pair's seed 3);
confidence high in 14. The pair's seed 1 names the same two effects in the other order (forward selection went on
from cubic_stiffening): `main` prints MISS there, comparing the strings; marked (ok). Of the two rows that were medium before, joint_settling seed 3 is now high (E falls
93%, was 67%) and cubic_stiffening seed 3 stays medium, by its floor (3.2: the baseline's folds refit its knee
within the top ring-down, where the read-out changes faster than the held factor follows), though its recalibrated
E falls 95% (was 64%, E after 5.68). The stage takes 70-90 s per case here (16-63 s before): each fit simulates
the ring-downs twice, each candidate is fitted from four valleys. joint_settling's drifts are still not identified
(each ring-down is one level and one place in the sequence).

Measured earlier on 2026-11-26 before the read-out factor (main), the jointed beam (voltage), seeds 1-3 (the same
columns; the floor the backbone's against the time simulation):

    none                                 seed 1: none                                 high   E   0.82 ->  0.82 (  -1%)  floor 0.29  ok     stage 17 s
    none                                 seed 2: none                                 high   E   1.15 ->  0.96 ( -16%)  floor 0.29  ok     stage 16 s
    none                                 seed 3: none                                 high   E   0.85 ->  0.85 (  -0%)  floor 0.30  ok     stage 22 s
    cubic_stiffening                     seed 1: cubic_stiffening                     high   E  14.26 ->  1.26 ( -91%)  floor 0.28  ok   k3 4.11e+08 (truth 3.68e+08)  stage 30 s
    cubic_stiffening                     seed 2: cubic_stiffening                     high   E  12.96 ->  1.17 ( -91%)  floor 0.31  ok   k3 4.05e+08 (truth 3.68e+08)  stage 24 s
    cubic_stiffening                     seed 3: cubic_stiffening                     medium E  15.75 ->  5.68 ( -64%)  floor 3.53  ok   k3 3.91e+08 (truth 3.68e+08)  stage 36 s
    elastic_softening                    seed 1: elastic_softening                    high   E   7.81 ->  1.07 ( -86%)  floor 0.17  ok   loss_ratio 0.269 (truth 0.3)  stage 25 s
    elastic_softening                    seed 2: elastic_softening                    high   E   8.09 ->  1.03 ( -87%)  floor 0.14  ok   loss_ratio 0.267 (truth 0.3)  stage 26 s
    elastic_softening                    seed 3: elastic_softening                    high   E   8.50 ->  1.00 ( -88%)  floor 0.15  ok   loss_ratio 0.27 (truth 0.3)  stage 61 s
    joint_settling                       seed 1: joint_settling                       high   E  10.22 ->  0.88 ( -91%)  floor 0.30  ok   Fs_drift 1 (truth 0.15); KT_drift 0.363 (truth 0.1); n_settle 3.82  stage 35 s
    joint_settling                       seed 2: joint_settling                       high   E  11.05 ->  0.90 ( -92%)  floor 0.32  ok   Fs_drift 0.0147 (truth 0.15); KT_drift 0.017 (truth 0.1); n_settle 2.65  stage 63 s
    joint_settling                       seed 3: joint_settling                       medium E  11.23 ->  3.70 ( -67%)  floor 2.72  ok   Fs_drift 0.238 (truth 0.15); KT_drift 0.147 (truth 0.1); n_settle 2.78  stage 61 s
    channel_delay                        seed 1: none                                 high   E   0.81 ->  0.81 (  -1%)  floor 0.29  ok     stage 17 s
    channel_delay                        seed 2: none                                 high   E   1.43 ->  0.90 ( -37%)  floor 0.30  ok     stage 21 s
    channel_delay                        seed 3: none                                 high   E   0.89 ->  0.86 (  -4%)  floor 0.31  ok     stage 21 s
    elastic_softening+cubic_stiffening   seed 1: elastic_softening+cubic_stiffening   high   E  10.84 ->  1.07 ( -90%)  floor 0.10  ok   loss_ratio 0.286 (truth 0.3); k3 4.22e+08 (truth 3.68e+08)  stage 23 s
    elastic_softening+cubic_stiffening   seed 2: elastic_softening+cubic_stiffening   high   E  10.26 ->  1.07 ( -90%)  floor 0.12  ok   loss_ratio 0.282 (truth 0.3); k3 4.32e+08 (truth 3.68e+08)  stage 28 s
    elastic_softening+cubic_stiffening   seed 3: elastic_softening+cubic_stiffening   high   E   9.90 ->  1.05 ( -89%)  floor 0.10  ok   loss_ratio 0.307 (truth 0.3); k3 4.05e+08 (truth 3.68e+08)  stage 23 s

The right name in 18 of 18 campaigns ('none' for the delay, which the stage does not try and says so); confidence
high in 16: the six 'none' and ten of the twelve with an effect, E falling by 86-92% in those ten. The two medium rows (seed 3 of cubic_stiffening and of joint_settling) have a
floor of 3.5 and 2.7 (rule.FLOOR_HIGH caps them) and E falling by 64-67%: there the calibration put the baseline's
macroslip knee inside the top ring-down's first windows, whose f and zeta change within a window (the read-out of
the time simulation reads 95.62 Hz and zeta 0.0212 where the backbone gives 96.0 Hz and 0.0173 one window later),
and the recalibrated model keeps it. A read-out factor like the sweeps' transient factor (the time simulation's
read-out over the backbone, taken at the fit and refreshed) would take that out: built since (above). joint_settling is named
but its drifts are not identified (Fs_drift 0.01 to 1 against 0.15): each ring-down is one level and one place in
the sequence, so the drift and the amplitude trade.

The base-driven Ministack before the factor (main; --rig ministack --only cubic_stiffening, seed 5):

    cubic_stiffening k3 5e11  seed 5: unexplained  low  E  2.32 ->  1.97 (-15%)  floor  1.58  MISS  stage 213 s
    cubic_stiffening k3 2e12  seed 5: unexplained  low  E 27.74 -> 26.27 ( -5%)  floor 19.99  MISS  stage 69 s

At 5e11 (fast scores baseline 1.97, cubic 1.77, floor 1.58) the decision is 'none', medium, which the time
simulation contradicts. At 2e12 the same cause as the beam's medium rows, stronger: the calibration (the Iwan
alone, made to follow a hardening backbone) put the macroslip knee at the largest amplitude read (phi_max 9.71e-5
in, q_max 9.72e-5 in, beta 1.2); the 10 g ring-down's time simulation then needs 8.4x the measured drive to start
at the measured amplitude and its first window reads 2168 Hz and zeta 0.057 where the backbone gives 2201 Hz and
0.025 (the run's E_f 50, E_zeta 60; the three lower runs E 0.9-3.4). Not met on the Ministack then; met with the read-out
factor and the valley starts (above).

After the recalibration's knee guard (2026-11-26, branch rd43 at 5fbb0ee: `discrepancy.recalibrate._chosen`, the
calibration's `pick_polished` on the windows' start amplitudes), beam and Ministack seeds 1-3, the machine shared
with two other jobs: the right name in 33 of 33, high in 31 (beam elastic_softening seed 2 medium: held-out 2.13
> 2; beam joint_settling seed 3 medium), and every named model validating, E after <= 1.26 (the two failing rows
above: Ministack quadratic_damping seed 1 3.51 -> 0.79, high; beam elastic_softening seed 2 3.31 -> 1.26):

    beam      none                                 seed 1: none                                 high   E   0.82 ->  0.76
    beam      none                                 seed 2: none                                 high   E   0.84 ->  0.78
    beam      none                                 seed 3: none                                 high   E   0.64 ->  0.57
    beam      cubic_stiffening                     seed 1: cubic_stiffening                     high   E  10.00 ->  0.76
    beam      cubic_stiffening                     seed 2: cubic_stiffening                     high   E  27.32 ->  0.80
    beam      cubic_stiffening                     seed 3: cubic_stiffening                     high   E  21.09 ->  0.59
    beam      elastic_softening                    seed 1: elastic_softening                    high   E   6.44 ->  0.87
    beam      elastic_softening                    seed 2: elastic_softening                    medium E   6.41 ->  1.26
    beam      elastic_softening                    seed 3: elastic_softening                    high   E   6.21 ->  0.67
    beam      joint_settling                       seed 1: joint_settling                       high   E  11.59 ->  0.69
    beam      joint_settling                       seed 2: joint_settling                       high   E  12.46 ->  0.76
    beam      joint_settling                       seed 3: joint_settling                       medium E  11.51 ->  0.64
    beam      channel_delay                        seed 1: none                                 high   E   0.82 ->  0.76
    beam      channel_delay                        seed 2: none                                 high   E   0.85 ->  0.79
    beam      channel_delay                        seed 3: none                                 high   E   0.71 ->  0.65
    beam      elastic_softening+cubic_stiffening   seed 1: cubic_stiffening+elastic_softening   high   E   8.78 ->  0.74
    beam      elastic_softening+cubic_stiffening   seed 2: cubic_stiffening+elastic_softening   high   E   7.96 ->  1.00
    beam      elastic_softening+cubic_stiffening   seed 3: cubic_stiffening+elastic_softening   high   E   7.91 ->  0.61
    ministack none                                 seed 1: none                                 high   E   1.11 ->  0.79
    ministack none                                 seed 2: none                                 high   E   1.10 ->  0.77
    ministack none                                 seed 3: none                                 high   E   1.08 ->  0.75
    ministack cubic_stiffening                     seed 1: cubic_stiffening                     high   E   1.85 ->  0.80
    ministack cubic_stiffening                     seed 2: cubic_stiffening                     high   E   1.81 ->  0.82
    ministack cubic_stiffening                     seed 3: cubic_stiffening                     high   E   1.75 ->  0.73
    ministack cubic_stiffening                     seed 1: cubic_stiffening                     high   E   3.86 ->  0.70
    ministack cubic_stiffening                     seed 2: cubic_stiffening                     high   E   3.86 ->  0.76
    ministack cubic_stiffening                     seed 3: cubic_stiffening                     high   E   3.94 ->  0.70
    ministack quadratic_damping                    seed 1: quadratic_damping                    high   E   6.26 ->  0.79
    ministack quadratic_damping                    seed 2: quadratic_damping                    high   E   6.30 ->  0.74
    ministack quadratic_damping                    seed 3: quadratic_damping                    high   E   6.19 ->  0.72
    ministack channel_delay                        seed 1: none                                 high   E   1.09 ->  0.72
    ministack channel_delay                        seed 2: none                                 high   E   1.10 ->  0.76
    ministack channel_delay                        seed 3: none                                 high   E   1.11 ->  0.72

A seed none of the rows above used, on main 64c0d34 (`--seeds 4`, the beam and the Ministack side by side,
2026-11-27 11:29-11:40): the right name in 11 of 11 (a pair, cubic + elastic, named both), high in 10, medium
in joint_settling (as seed 3 above); E falls 54-94% where an effect is hidden; k3 within 9% of the truth, the
loss ratio within 7%, c2 1.2. The beam, then the Ministack:

    none s4: none high E 0.84 -> 0.78 ( -6%) floor 0.01 ok stage 53 s
    cubic_stiffening s4: cubic_stiffening high E 9.49 -> 1.24 ( -87%) floor 0.07 ok k3 4.02e+08 (truth 3.68e+08) stage 30 s
    elastic_softening s4: elastic_softening high E 6.16 -> 1.03 ( -83%) floor 0.02 ok loss_ratio 0.285 (truth 0.3) stage 30 s
    joint_settling s4: joint_settling medium E 11.69 -> 0.75 ( -94%) floor 0.02 ok Fs_drift 0.18 (truth 0.15); KT_drift 0.0668 (truth 0.1); n_settle 2.83 stage 29 s
    channel_delay s4: none high E 0.84 -> 0.79 ( -6%) floor 0.00 ok stage 54 s
    elastic_softening+cubic_stiffening s4: cubic_stiffening+elastic_softening high E 7.69 -> 0.71 ( -91%) floor 0.27 ok k3 3.6e+08 (truth 3.68e+08); loss_ratio 0.32 (truth 0.3) stage 47 s

    none s4: none high E 1.17 -> 0.84 ( -28%) floor 0.01 ok stage 44 s
    cubic_stiffening s4: cubic_stiffening high E 1.81 -> 0.83 ( -54%) floor 0.03 ok k3 4.79e+11 (truth 5e+11) stage 105 s
    cubic_stiffening s4: cubic_stiffening high E 2.75 -> 0.80 ( -71%) floor 0.02 ok k3 1.96e+12 (truth 2e+12) stage 57 s
    quadratic_damping s4: quadratic_damping high E 6.44 -> 0.72 ( -89%) floor 0.02 ok c2 1.2 stage 99 s
    channel_delay s4: none high E 1.16 -> 0.82 ( -29%) floor 0.01 ok stage 49 s
"""
import argparse
import sys
import tempfile
import time
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).parents[2]))
from tests._support.decay_campaign import calibrate_and_diagnose, ministack_ring_downs, ring_down_campaign  # noqa: E402

from jointcal.discrepancy import DiscrepancySettings  # noqa: E402

CONFIG = yaml.safe_load((Path(__file__).parents[2] / "workflow" / "config" / "config.yaml").read_text())
M_RIG = 1.05 / 386.089  # the rig's mode: the 1 lbf beam and the 0.05 lbf armature
CASES = [
    ("none", {}, "none"),
    ("cubic_stiffening", {"k3": 1e6}, "cubic_stiffening"),
    ("elastic_softening", {"loss_ratio": 0.3}, "elastic_softening"),
    ("joint_settling", {"Fs_drift": 0.15, "KT_drift": 0.1}, "joint_settling"),
    ("channel_delay", {"tau_s": 4e-4}, "none"),  # what a decay shows of it: nothing
    ("elastic_softening", {"loss_ratio": 0.3, "also": {"name": "cubic_stiffening", "params": {"k3": 1e6}}},
     "elastic_softening+cubic_stiffening"),
]


MINISTACK = [  # the base-driven Ministack (first assembly, four ring-downs 0.3-10 g, 0.1% noise), hidden strengths
    ("none", {}, "none"),  # the library's defaults
    ("cubic_stiffening", {"k3": 5e11}, "cubic_stiffening"),
    ("cubic_stiffening", {"k3": 2e12}, "cubic_stiffening"),
    ("quadratic_damping", {}, "quadratic_damping"),
    ("channel_delay", {"tau_s": 4e-5}, "none"),
]


def _truth_value(name: str, value: float, rig: str) -> float:
    return value / M_RIG if name == "k3" and rig == "beam" else value


def run_case(effect: str, params: dict, seed: int, rig: str = "beam") -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        p = {k: v for k, v in params.items() if k != "also"}
        t0 = time.perf_counter()
        if rig == "beam":
            ring_down_campaign(folder, effect, p, seed=seed, also=params.get("also"))
        else:
            ministack_ring_downs(folder, effect, p or None, seed=seed)
        t1 = time.perf_counter()
        d = calibrate_and_diagnose(folder, DiscrepancySettings.from_config(CONFIG["discrepancy"]),
                                   assembly="beam" if rig == "beam" else "first")["diagnosis"]
        t2 = time.perf_counter()
    eff = d["recalibrated"]["effect_parameters"]
    truth = {**p, **(params.get("also", {}).get("params", {}))}
    got = "; ".join(f"{k} {v['value']:.3g} (truth {_truth_value(k, truth[k], rig):.3g})" if k in truth else
                    f"{k} {v['value']:.3g}" for k, v in eff.items())
    return dict(effect=d["effect"], confidence=d["confidence"], E_before=d["metric_before"], E_after=d["metric_after"],
                floor=d["fast_model_floor"]["E"], params=got, stage_s=t2 - t1, total_s=t2 - t0,
                not_seen=",".join(d["not_seen_by_decays"]),
                scores=" ".join(f"{c['name']} {c['held_out_score']:.2f}" for c in [{'name': 'baseline', **d['baseline']}, *d['candidates'][:3]]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--only", default=None)
    ap.add_argument("--out", default=None)
    ap.add_argument("--rig", default="beam", choices=("beam", "ministack"))
    a = ap.parse_args(argv)
    lines = []
    for effect, params, want in (CASES if a.rig == "beam" else MINISTACK):
        label = want if effect != "channel_delay" else "channel_delay"
        if a.only and a.only not in (effect, label):
            continue
        for seed in [int(s) for s in a.seeds.split(",")]:
            r = run_case(effect, params, seed, a.rig)
            ok = "ok" if set(r["effect"].split("+")) == set(want.split("+")) else "MISS"  # a pair in either order
            change = r["E_after"] / r["E_before"] - 1
            line = (f"{label:36s} seed {seed}: {r['effect']:36s} {r['confidence']:6s} E {r['E_before']:6.2f} -> "
                    f"{r['E_after']:5.2f} ({change:+5.0%})  floor {r['floor']:.2f}  {ok:4s} {r['params']}  "
                    f"stage {r['stage_s']:.0f} s; scores {r['scores']}")
            print(line, flush=True)
            lines.append(line)
            if a.out:
                Path(a.out).write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
