// Listens on an LCM URL for a few seconds and decodes every message the way lcm-spy does:
// its lcm.spy.LCMTypeDatabase scans the class path for LCM types and looks each message's
// fingerprint up. Prints one line per channel given and exits 1 when a message was
// undecodable or a channel never spoke. Usage:
//   java -cp trajroi_lcmtypes.jar:lcm.jar:. SpyDecodeCheck URL SECONDS CHANNEL...
import java.io.DataInputStream;
import java.io.ByteArrayInputStream;
import java.util.Map;
import java.util.TreeMap;

public class SpyDecodeCheck implements lcm.lcm.LCMSubscriber {
    private final lcm.spy.LCMTypeDatabase types = new lcm.spy.LCMTypeDatabase();
    private final Map<String, long[]> counts = new TreeMap<>();  // decoded, undecodable

    public synchronized void messageReceived(lcm.lcm.LCM lcm, String channel, lcm.lcm.LCMDataInputStream in) {
        long[] c = counts.computeIfAbsent(channel, k -> new long[2]);
        try {
            byte[] data = new byte[in.available()];
            in.readFully(data);
            long fingerprint = new DataInputStream(new ByteArrayInputStream(data)).readLong();
            Class<?> cls = types.getClassByFingerprint(fingerprint);
            if (cls == null) {
                c[1]++;
                return;
            }
            cls.getConstructor(java.io.DataInput.class).newInstance(new DataInputStream(new ByteArrayInputStream(data)));
            c[0]++;
        } catch (Exception e) {
            c[1]++;
        }
    }

    public static void main(String[] args) throws Exception {
        SpyDecodeCheck check = new SpyDecodeCheck();
        lcm.lcm.LCM lcm = new lcm.lcm.LCM(args[0]);
        for (int i = 2; i < args.length; i++) lcm.subscribe(args[i], check);
        Thread.sleep((long) (Double.parseDouble(args[1]) * 1000));
        lcm.close();
        boolean ok = true;
        synchronized (check) {
            for (int i = 2; i < args.length; i++) {
                long[] c = check.counts.get(args[i]);
                if (c == null) {
                    System.out.println(args[i] + ": no message");
                    ok = false;
                }
            }
            for (Map.Entry<String, long[]> e : check.counts.entrySet()) {
                long[] c = e.getValue();
                System.out.println(e.getKey() + ": " + c[0] + " decoded, " + c[1] + " undecodable");
                if (c[1] > 0) ok = false;
            }
        }
        System.exit(ok ? 0 : 1);
    }
}
