// Decodes every event of an LCM log the way lcm-spy does, and fails if one
// cannot be decoded. lcm-spy finds message classes with
// lcm.spy.LCMTypeDatabase, which scans the CLASSPATH environment variable
// (plus java.class.path) for classes with an LCM_FINGERPRINT and looks each
// message up by the fingerprint in its first 8 bytes. This check uses that
// same database, so it passes exactly when lcm-spy, started with the vimot
// jar in CLASSPATH, can show every message.
//
// Run as a single-file program (Java 11+), lcm.jar on -cp, the vimot jar in
// CLASSPATH like scripts/lcm-spy.sh sets it:
//   CLASSPATH=vimot_lcmtypes.jar java -cp lcm.jar LcmSpyDecodeCheck.java <log> <events>

import java.io.ByteArrayInputStream;
import java.io.ByteArrayOutputStream;
import java.io.DataInput;
import java.io.DataInputStream;
import java.io.DataOutputStream;
import java.io.EOFException;
import java.util.Arrays;

import lcm.lcm.LCMEncodable;
import lcm.logging.Log;
import lcm.spy.LCMTypeDatabase;

public class LcmSpyDecodeCheck {
    public static void main(String[] args) throws Exception {
        if (args.length != 2) {
            System.err.println("usage: LcmSpyDecodeCheck <log> <expected number of events>");
            System.exit(2);
        }
        final int expected = Integer.parseInt(args[1]);
        final LCMTypeDatabase db = new LCMTypeDatabase();
        final Log log = new Log(args[0], "r");
        int events = 0;
        int failures = 0;
        while (true) {
            final Log.Event ev;
            try {
                ev = log.readNext();
            } catch (EOFException end) {
                break;
            }
            ++events;
            final long fingerprint = new DataInputStream(new ByteArrayInputStream(ev.data)).readLong();
            final Class<?> cls = db.getClassByFingerprint(fingerprint);
            if (cls == null) {
                System.err.printf("FAIL %s: no class with fingerprint %016x on the CLASSPATH%n",
                                  ev.channel, fingerprint);
                ++failures;
                continue;
            }
            if (!cls.getName().startsWith("vimot.")) {
                System.err.printf("FAIL %s: decoded as %s, not a vimot type%n", ev.channel, cls.getName());
                ++failures;
                continue;
            }
            // The constructor lcm-spy calls; it rejects a wrong fingerprint or short data.
            final LCMEncodable msg = (LCMEncodable) cls.getConstructor(DataInput.class)
                .newInstance(new DataInputStream(new ByteArrayInputStream(ev.data)));
            final ByteArrayOutputStream again = new ByteArrayOutputStream();
            msg.encode(new DataOutputStream(again));
            if (!Arrays.equals(again.toByteArray(), ev.data)) {
                System.err.printf("FAIL %s: %s re-encodes to different bytes%n", ev.channel, cls.getName());
                ++failures;
                continue;
            }
            System.out.printf("ok   %-22s %s%n", ev.channel, cls.getName());
        }
        log.close();
        if (events != expected) {
            System.err.printf("FAIL read %d events, expected %d%n", events, expected);
            ++failures;
        }
        System.exit(failures == 0 ? 0 : 1);
    }
}
