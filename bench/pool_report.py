"""The "Several instances" section of docs/benchmarks.md from the measurements of bench/pool_throughput.py: throughput tables,
where scaling stops, a model for N hosts, the failover trial and the target verdicts."""
import numpy as np

TARGET_SPEEDUP = 1.6  # pool of 2 instances against one, K = 1000 Panda backprop
LINKS = (('1 GbE', 0.117e9), ('10 GbE', 1.17e9))  # [bytes/s] payload a link carries
HOSTS = (1, 2, 4, 8, 16)
LABELS = ('client', 'pool 1', 'pool 2', 'pool 4')


def median_row(samples):
    """Medians over the windows: calls/s, node cores (per instance), client cores, load, compilers."""
    rates = [s[0] for s in samples]
    order = np.argsort(rates)[len(rates) // 2]  # the median window: its CPU figures go with its rate
    rate, cores, client, _, _ = samples[order]
    return rate, cores, client, float(np.median([s[3] for s in samples])), int(np.median([s[4] for s in samples]))


def throughput_table(result):
    workload = result['workload']
    megabytes = (workload.request_bytes + workload.response_bytes) / 1e6
    base = one_instance(result)
    lines = ['#### %s' % workload.name, '',
             '%.2f MB per call (%.2f MB request, %.2f MB answer).' % (
                 megabytes, workload.request_bytes / 1e6, workload.response_bytes / 1e6), '',
             '| client | calls/s | MB/s | vs one instance (the faster row) | nodes\' CPU [cores] | '
             'client CPU [cores] | '
             'answer == one instance |', '|---|---|---|---|---|---|---|']
    for label in LABELS:
        rate, cores, client, _, _ = median_row(result['samples'][label])
        lines.append('| %s | %.2f | %.0f | %.2fx | %s | %.2f | %s |' % (
            'RigidBodyClient' if label == 'client' else 'RigidBodyPool, %s instance%s' % (
                label.split()[1], '' if label == 'pool 1' else 's'),
            rate, rate * megabytes, rate / base, ' + '.join('%.2f' % c for c in cores if c > 0.005) or '0',
            client, 'yes' if result['equal'][label] else '**NO**'))
    for streams, rate in sorted(result['echo'].items()):
        lines.append('| transport alone: ~echo of the same bytes in %d stream%s | %.2f | %.0f | | | | |' % (
            streams, '' if streams == 1 else 's', rate, rate * megabytes))
    return lines


def one_instance(result):
    """The faster of the two one-instance rows (RigidBodyClient, a pool of 1): the baseline."""
    return max(median_row(result['samples']['client'])[0], median_row(result['samples']['pool 1'])[0])


def bottleneck(result):
    """Where the 2-instance pool stops: a sentence from its CPU use and the transport's rate."""
    workload = result['workload']
    megabytes = (workload.request_bytes + workload.response_bytes) / 1e6
    rate, cores, client, load, compilers = median_row(result['samples']['pool 2'])
    used = sum(cores) + client
    echo = result['echo'][2]  # the same two shards through the transport alone
    words = ['%s: the 2-instance pool used %.2f cores (nodes %.2f, client %.2f) of 2' % (
        workload.name, used, sum(cores), client)]
    if used >= 1.6:
        words.append('so it is bound by the cores')
    if rate >= 0.7 * echo:
        words.append('and ran at %.0f%% of the rate of the transport alone (%.0f MB/s: ~echo of the same two '
                     'shards), so the transport bounds it' % (100 * rate / echo, echo * megabytes))
    else:
        words.append('and moved %.0f MB/s where the transport alone moves %.0f MB/s (~echo of the same two '
                     'shards)' % (rate * megabytes, echo * megabytes))
    words.append('(machine load %.1f, %d compilers running)' % (load, compilers))
    return ', '.join(words) + '.'


def model(result):
    """calls/s of a pool over N hosts, one instance each: 1 / max(t_node / N, t_client, bytes / link).
    Returns (a line with the inputs, table rows per link)."""
    workload = result['workload']
    rate, cores, client, _, _ = median_row(result['samples']['client'])
    node_seconds, client_seconds = sum(cores) / rate, client / rate  # CPU per call, one instance
    size = workload.request_bytes + workload.response_bytes
    inputs = '- %s: t_node = %.1f ms, t_client = %.1f ms, %.1f MB per call' % (
        workload.name, 1e3 * node_seconds, 1e3 * client_seconds, size / 1e6)
    rows = []
    for name, bandwidth in LINKS:
        rates = [1.0 / max(node_seconds / n, client_seconds, size / bandwidth) for n in HOSTS]
        bounds = {'the link': size / bandwidth, 'the client': client_seconds, 'the nodes': node_seconds / HOSTS[-1]}
        rows.append('| %s, %s | %s | %s |' % (workload.name, name, ' | '.join('%.1f' % r for r in rates),
                                              max(bounds, key=bounds.get)))
    return inputs, rows


def verdicts(scenes):
    lines = []
    backprop = scenes['panda'][0][0]
    one = one_instance(backprop)
    two = median_row(backprop['samples']['pool 2'])[0]
    equal = all(backprop['equal'].values())
    speedup, echo = two / one, backprop['echo']
    lines.append('- **Pool of 2 on 2 cores, K = 1000 Panda backprop (all vertices): >= %.1fx one instance, bit for '
                 'bit**: %.2fx, answers %s: **%s**. %s The transport alone (~echo, no computation) carries these '
                 'bytes at %.1f calls/s in one stream and %.1f in the two shards of a pool of 2: %.2fx one '
                 'instance is the most any pool of 2 can reach on this machine.' % (
                     TARGET_SPEEDUP, speedup, 'equal' if equal else 'DIFFERENT',
                     'met' if speedup >= TARGET_SPEEDUP and equal else 'missed', bottleneck(backprop),
                     echo[1], echo[2], echo[2] / one))
    for result in scenes['panda'][0][1:] + scenes['humanoid'][0]:
        ratio = median_row(result['samples']['pool 2'])[0] / one_instance(result)
        lines.append('- %s: pool of 2 at %.2fx one instance. %s' % (result['workload'].name, ratio, bottleneck(result)))
    failed, equal_calls, log = scenes['panda'][1]
    lines.append('- **Failover: one instance killed mid-call, 0 failed calls, answer unchanged**: %d failed calls, '
                 '%d of 8 answers equal to one instance\'s: **%s**. The pool logged: %s' % (
                     failed, equal_calls, 'met' if failed == 0 and equal_calls == 8 else 'missed',
                     '; '.join('"%s"' % line for line in log[:2]) or 'nothing'))
    return lines


def report(scenes, args, machine, seconds):
    lines = ['## Several instances: pool throughput', '',
             'Generated by `bench/pool_throughput.py` (%.0f s; %s; windows of %g s, median of %d, sizes '
             'interleaved). Alone: `source $DRB_WORKSPACE/devel/setup.bash && bench/pool_throughput.py '
             '--output pool.md`. The instances are separate `rigid_body_server` processes on this machine '
             '(~publish_rate 1 Hz, 4 service threads each); the client is one Python process: '
             '`RigidBodyClient` alone, or `RigidBodyPool` over the first 1, 2 or 4 instances (one worker '
             'thread per instance, shards sized by measured throughput). CPU is read from /proc per '
             'process over the window (1.00 = one core busy).' % (seconds, machine, args.seconds, args.repeats),
             '', '### Targets', '']
    lines += verdicts(scenes)
    lines += ['', '### Calls per second and MB/s', '']
    for scene in ('panda', 'humanoid'):
        for result in scenes[scene][0]:
            lines += throughput_table(result) + ['']
    lines += ['### Where scaling stops', '']
    for scene in ('panda', 'humanoid'):
        lines += ['- ' + bottleneck(result) for result in scenes[scene][0]]
    lines += ['', '### A model for N hosts', '',
              'One instance per host, each shard on its own host\'s core, the client on its own machine. From '
              'the one-instance row: t_node = the nodes\' CPU per call, t_client = the client\'s CPU per call '
              '(serialising and receiving: it does not shrink with N), and the bytes per call, which all cross '
              'the client\'s link. Then calls/s(N) = 1 / max(t_node / N, t_client, bytes / link rate). On one '
              'machine the instances share its cores and memory bandwidth, so the measured rows above are the '
              'N = 1 point and a lower bound for the rest.', '',
              ]
    models = [model(result) for scene in ('panda', 'humanoid') for result in scenes[scene][0]]
    lines += [inputs for inputs, _ in models]
    lines += ['', '| workload, client link | %s | bound at N = %d |' % (
        ' | '.join('N = %d [calls/s]' % n for n in HOSTS), HOSTS[-1]), '|---|%s---|' % ('---|' * len(HOSTS))]
    lines += [row for _, rows in models for row in rows]
    lines += ['', '### Notes', '',
              '- **The client\'s transport.** `RigidBodyClient` writes a request\'s arrays to the socket from the '
              'caller\'s numpy buffers and receives an answer into one buffer whose slices become the returned '
              'arrays (`diff_rigid_body.tcpros`). `rospy.ServiceProxy` (with `numpy_msg`) stages both directions '
              'in a `BytesIO` that it shrinks to empty after each message, so every large call maps fresh pages; '
              'where writing fresh memory is slow (see the machine line above) that dominates: the client trajectory '
              'section above times both on the same bytes.',
              '- **Shards.** A pool cuts K configurations into contiguous shards in proportion to each instance\'s '
              'measured configurations per second (smoothed over calls) and joins the answers in order; its own '
              'work per call (cutting, two thread hand-offs per shard, joining) is about 0.15 ms. A pool of 1 '
              'differs from `RigidBodyClient` only by that and by running the call on a worker thread.',
              '- **One machine is not N hosts.** Here the client and the instances share 2 cores and one memory '
              'system, and other work may run (the load is given per figure). A pool of n > 2 cannot add cores; '
              'it adds parallel transfers, which help where per-message costs grow faster than the message.']
    return '\n'.join(lines) + '\n'
